#!/usr/bin/env bash
# test_install.sh - `cmake --install` into a temporary prefix gives what a Debian machine
# expects, and a program builds against the installed library and runs, found both ways
# a user finds it: find_package(grainpack) (shared and static) and pkg-config (shared and
# static), including <grainpack/grainpack.h> alone in strict C11 (-pedantic, warnings as
# errors). The libraries offer exactly the functions the installed headers declare: the
# shared one exports nothing else, the archive defines no other global name (internal
# helpers such as front_* are hidden, or local). The systemd unit passes `systemd-analyze verify`, and `systemd-analyze
# security` rates its sandbox (both where systemd-analyze exists). A configuration
# without the tests looks for neither node nor python.
# Usage: test_install.sh BUILD_DIR SOURCE_DIR LIBDIR SBINDIR [CONSUMER_FLAGS]
#   LIBDIR, SBINDIR: as configured (CMAKE_INSTALL_LIBDIR, CMAKE_INSTALL_SBINDIR);
#   CONSUMER_FLAGS: compiler flags the consumer needs too (the sanitizers', in such a build).
set -u
build=$1 src=$2 libdir=$3 sbindir=$4 cflags=${5:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
# Worst overall exposure `systemd-analyze security` may give the unit (0 best, 10 worst;
# it calls 1.0 to 1.9 "OK"). The unit rates 1.2 with systemd 252 (Debian 12): above 1.5 a
# hardening option was lost.
MAX_EXPOSURE=1.5

cmake --install "$build" --prefix "$prefix" > "$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; fail "cmake --install"; }
echo "installed $(grep -c '^-- \(Installing\|Up-to-date\)' "$tmp/install.log") files into a temporary prefix"

for f in bin/grainpack "$sbindir/grainpackd" "$libdir/libgrainpack.a" "$libdir/libgrainpack.so" \
         include/grainpack/version.h include/grainpack/pipeline.h \
         "$libdir/cmake/grainpack/grainpackConfig.cmake" "$libdir/cmake/grainpack/grainpackConfigVersion.cmake" \
         "$libdir/pkgconfig/grainpack.pc" lib/systemd/system/grainpackd.service lib/sysusers.d/grainpack.conf \
         share/man/man1/grainpack.1 share/man/man8/grainpackd.8 share/grainpack/examples/iron.json \
         share/grainpack/openapi.yaml share/doc/grainpack/README.md share/doc/grainpack/LICENSE \
         share/doc/grainpack/method.md; do
  [ -e "$prefix/$f" ] || fail "$f not installed"
done
soname=$(readelf -d "$prefix/$libdir/libgrainpack.so" 2>/dev/null | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')
[ "$soname" = "libgrainpack.so.0" ] && [ -e "$prefix/$libdir/$soname" ] || fail "SONAME '$soname'"
echo "shared library: SONAME $soname"
! grep -q -- "-W\|-fsanitize\|-flto" "$prefix/$libdir/cmake/grainpack/grainpackTargets.cmake" ||
  fail "the exported targets carry the project's compiler flags"

# the public API: the umbrella header alone, in strict C11, and the functions it declares
# (GCC's -aux-info lists every prototype it saw, with its file), which must be exactly
# what the libraries export. The headers include nothing but the C library's and their own.
strict="-std=c11 -Wall -Wextra -Werror -pedantic"
printf '#include <grainpack/grainpack.h>\nint main(void) { return gp_version()[0] == 0; }\n' > "$tmp/umbrella.c"
if cc $strict -I"$prefix/include" -aux-info "$tmp/aux.txt" -c "$tmp/umbrella.c" -o "$tmp/umbrella.o" 2> "$tmp/umbrella.log"; then
  grep "^/\* $prefix/include/grainpack/" "$tmp/aux.txt" | grep -v '\*/ static ' |
    sed -n 's/.*\*\/ extern [^(]*[ *]\(gp_[a-z0-9_]*\) (.*/\1/p' | sort -u > "$tmp/declared"
  echo "grainpack/grainpack.h alone compiles with $strict: $(wc -l < "$tmp/declared") functions declared"
else
  cat "$tmp/umbrella.log"; fail "grainpack/grainpack.h alone does not compile with $strict"
fi
others=$(grep -h '^#include <' "$prefix"/include/grainpack/*.h | sort -u |
         grep -v '<\(stddef\|stdint\|stdio\|stdarg\|stdatomic\)\.h>\|<atomic>') &&
  fail "the installed headers include $others"
nm -D --defined-only "$prefix/$libdir/libgrainpack.so" | awk '{print $NF}' | sort -u > "$tmp/exported"
if cmp -s "$tmp/declared" "$tmp/exported"; then
  echo "shared library: exports the $(wc -l < "$tmp/exported") functions of the headers, nothing else"
else
  fail "the shared library's exports differ from the headers' functions:" \
       "$(diff "$tmp/declared" "$tmp/exported" | grep '^[<>]' | head -20 | tr '\n' ' ')"
fi
# the archive: global names defined strongly (T, D, B, R); weak and unique ones (V, W,
# u) are C++ template instances, merged with a program's own copies by the linker
nm -g --defined-only "$prefix/$libdir/libgrainpack.a" | awk 'NF == 3 && $2 ~ /^[TDBR]$/ {print $3}' |
  sort -u > "$tmp/archived"
if cmp -s "$tmp/declared" "$tmp/archived"; then
  echo "static library: defines the $(wc -l < "$tmp/archived") functions of the headers as its only global names"
else
  fail "the archive's global names differ from the headers' functions:" \
       "$(diff "$tmp/declared" "$tmp/archived" | grep '^[<>]' | head -20 | tr '\n' ' ')"
fi

# the installed programs, the installed examples, the man pages
version=$(sed -n 's/#define GP_VERSION "\(.*\)"/\1/p' "$prefix/include/grainpack/version.h")
[ "$("$prefix/bin/grainpack" --version)" = "grainpack $version" ] || fail "grainpack --version"
[ "$("$prefix/$sbindir/grainpackd" --version)" = "grainpackd $version" ] || fail "grainpackd --version"
"$prefix/bin/grainpack" run "$prefix/share/grainpack/examples/iron.json" -f csv -o "$tmp/iron.csv" || fail "installed grainpack run"
[ "$(wc -l < "$tmp/iron.csv")" -gt 900 ] || fail "installed grainpack packed $(wc -l < "$tmp/iron.csv") lines"
for page in man1/grainpack.1 man8/grainpackd.8; do
  grep -q '^\.SH SYNOPSIS' "$prefix/share/man/$page" && grep -q -e 'max\\-disks' -e 'max-disks' "$prefix/share/man/$page" ||
    fail "$page has no synopsis or options"
done

# find_package: a C-only project, shared and static
export CFLAGS="$cflags" LDFLAGS="$cflags"
if cmake -S "$src/tests/install/consumer" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$prefix" \
       -DCMAKE_BUILD_TYPE=Release > "$tmp/consumer.log" 2>&1 &&
   cmake --build "$tmp/consumer" >> "$tmp/consumer.log" 2>&1; then
  for kind in shared static; do
    out=$("$tmp/consumer/consumer_$kind") || fail "consumer_$kind (find_package) failed: $out"
    echo "find_package, $kind: $out"
  done
  readelf -d "$tmp/consumer/consumer_shared" | grep -q "NEEDED.*libgrainpack.so.0" || fail "consumer_shared does not use the shared library"
  ! readelf -d "$tmp/consumer/consumer_static" | grep -q "libgrainpack" || fail "consumer_static uses the shared library"
else
  cat "$tmp/consumer.log"; fail "find_package consumer did not build"
fi

# pkg-config: cc and nothing else, shared and static
export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
if cc $strict $cflags "$src/tests/install/consumer/consumer.c" -o "$tmp/pc_shared" \
      $(pkg-config --cflags --libs grainpack) -lm 2> "$tmp/pc.log"; then
  out=$(LD_LIBRARY_PATH="$prefix/$libdir" "$tmp/pc_shared") || fail "pc_shared failed: $out"
  echo "pkg-config, shared: $out"
else
  cat "$tmp/pc.log"; fail "pkg-config consumer did not build"
fi
if cc $strict $cflags "$src/tests/install/consumer/consumer.c" -o "$tmp/pc_static" \
      $(pkg-config --cflags grainpack) $(pkg-config --static --libs grainpack | sed 's/-lgrainpack\b/-l:libgrainpack.a/') 2> "$tmp/pc.log"; then
  out=$("$tmp/pc_static") || fail "pc_static failed: $out"
  echo "pkg-config, static: $out"
else
  cat "$tmp/pc.log"; fail "pkg-config static consumer did not build"
fi
unset CFLAGS LDFLAGS

# the systemd unit
unit=$prefix/lib/systemd/system/grainpackd.service
grep -q "^ExecStart=$prefix/$sbindir/grainpackd\$" "$unit" || fail "ExecStart is not the installed grainpackd: $(grep ExecStart "$unit")"
if command -v systemd-analyze > /dev/null; then
  if out=$(systemd-analyze verify --man=no "$unit" 2>&1); then
    echo "systemd-analyze verify: ok${out:+ ($out)}"
  else
    fail "systemd-analyze verify: $out"
  fi
  exposure=$(systemd-analyze security --offline=true "$unit" 2>&1 | sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p')
  if [ -z "$exposure" ]; then
    fail "systemd-analyze security gave no exposure level"
  elif awk -v e="$exposure" -v m="$MAX_EXPOSURE" 'BEGIN { exit !(e > m) }'; then
    systemd-analyze security --offline=true "$unit" 2>&1 | grep '✗' | head -20
    fail "systemd-analyze security: exposure $exposure, more than $MAX_EXPOSURE"
  else
    echo "systemd-analyze security: overall exposure $exposure (at most $MAX_EXPOSURE)"
  fi
else
  echo "systemd-analyze not found: the unit was not verified"
fi

# a configuration without the tests needs neither node nor python (a Debug one: it skips
# the link-time optimisation probe, half the time of a configuration)
if cmake -S "$src" -B "$tmp/notests" -DGP_BUILD_TESTS=OFF -DGP_BUILD_BENCH=OFF -DGP_MAN_PAGES=OFF \
       -DCMAKE_BUILD_TYPE=Debug > "$tmp/notests.log" 2>&1; then
  ! grep -q "^GP_NODE\|^GP_PYTHON3" "$tmp/notests/CMakeCache.txt" || fail "configured without tests, CMake still looked for node or python"
  echo "configured with GP_BUILD_TESTS=OFF: node and python not looked for"
else
  cat "$tmp/notests.log"; fail "configuring with GP_BUILD_TESTS=OFF failed"
fi

if [ "$failures" -gt 0 ]; then
  echo "$failures check(s) failed"
  exit 1
fi
echo "ok   test_install"
