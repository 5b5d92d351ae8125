# daemon.sh - sourced by the download benchmarks: builds grainpackd in Release (unless
# GP_DAEMON names one), starts it with one worker and the extra arguments given, in a
# temporary data directory removed at exit. Sets GP_DAEMON, dir, pid, base (its URL),
# load_start (the load average before), and rss KEY (a VmRSS/VmHWM of the daemon, in kB).
if [ -z "${GP_DAEMON:-}" ]; then
  cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build build-bench -j"$(nproc)" --target grainpackd > /dev/null
  GP_DAEMON=./build-bench/server/grainpackd
fi
dir=$(mktemp -d)
"$GP_DAEMON" --port 0 --data-dir "$dir" --ready-file "$dir/port" --workers 1 "$@" 2> "$dir/log" &
pid=$!
trap 'kill "$pid" 2> /dev/null; wait "$pid" 2> /dev/null; rm -rf "$dir"' EXIT
while [ ! -s "$dir/port" ]; do sleep 0.05; done
base="http://127.0.0.1:$(cat "$dir/port")"
load_start=$(cut -d' ' -f1 /proc/loadavg)
rss() { awk -v k="$1:" '$1 == k {print $2}' "/proc/$pid/status"; }

# download_rows URL FORMAT... - one markdown row a format: URL?f=FORMAT downloaded alone, its
# bytes and time, and the daemon's RSS before, at its peak during and after the download.
download_rows() {
  local url=$1 fmt before out peak after total bytes
  shift
  echo "| format | bytes | time | RSS before | peak during | after | peak - before |"
  echo "| --- | --- | --- | --- | --- | --- | --- |"
  for fmt in "$@"; do
    before=$(rss VmRSS)
    echo 5 > "/proc/$pid/clear_refs"  # VmHWM counts from here
    out=$(curl -s -o /dev/null -w '%{time_total} %{size_download}' "$url?f=$fmt")
    peak=$(rss VmHWM)
    after=$(rss VmRSS)
    read -r total bytes <<< "$out"
    python3 -c "print(f'| $fmt | {$bytes / 1e6:.1f} MB | {$total:.2f} s | {$before / 1024:.1f} MB |'
                      f' {$peak / 1024:.1f} MB | {$after / 1024:.1f} MB | +{($peak - $before) / 1024:.1f} MB |')"
  done
}

# concurrent_downloads N URL LABEL FORMAT... - N downloads of URL?f=FORMAT at once (the
# formats in turn, every second one gzip) and one line: their time and the daemon's memory.
concurrent_downloads() {
  local n=$1 url=$2 label=$3
  shift 3
  local formats=("$@") idle start end peak enc k
  idle=$(rss VmRSS)
  echo 5 > "/proc/$pid/clear_refs"  # VmHWM counts from here
  start=$(date +%s.%N)
  for k in $(seq 0 $((n - 1))); do
    enc=identity
    [ $((k % 2)) -eq 1 ] && enc=gzip
    curl -s -o /dev/null -H "Accept-Encoding: $enc" "$url?f=${formats[$((k % ${#formats[@]}))]}" &
  done
  wait $(jobs -p | grep -v "^$pid$") 2> /dev/null || true
  end=$(date +%s.%N)
  peak=$(rss VmHWM)
  echo
  python3 -c "print(f'{$n} concurrent downloads ($label, half gzip): {$end - $start:.1f} s;'
                    f' daemon RSS before {$idle / 1024:.1f} MB, peak {$peak / 1024:.1f} MB'
                    f' (+{($peak - $idle) / 1024:.1f} MB), after {$(rss VmRSS) / 1024:.1f} MB')"
}
