#!/usr/bin/env bash
# pg_server.sh - a private PostgreSQL server for the tests (Debian's postgresql package):
# `start STATE` runs initdb into a new temporary directory and starts the server on a
# Unix socket in it (no TCP port: nothing to collide with), password authentication
# only; it writes the server's connection URI (without the password, which the tests
# pass as PGPASSWORD) into the file STATE. `stop STATE` stops it and removes everything.
# initdb and the server refuse to run as root: as root (CI), they run as `nobody` in a
# directory that user owns.
set -euo pipefail
cmd=$1
state=$2
# the password of the tests' superuser (the tests give it through PGPASSWORD, as a user
# of grainpackd would; the service tests check that no log shows it)
password=${GP_TEST_PG_PASSWORD:-grainpack-test-password}

stop() {
  [ -f "$state" ] || return 0
  local dir
  dir=$(sed -n 's/^dir=//p' "$state")
  if [ -n "$dir" ] && [ -d "$dir/data" ]; then
    as_owner "$dir" pg_ctl -D "$dir/data" -m immediate -w stop > /dev/null 2>&1 || true
  fi
  [ -n "$dir" ] && rm -rf "$dir"
  rm -f "$state"
}

# runs a PostgreSQL program as the owner of directory $1
as_owner() {
  local dir=$1 prog=$2
  shift 2
  local bin
  bin=$(ls -d /usr/lib/postgresql/*/bin | sort -V | tail -n 1)
  if [ "$(id -u)" -eq 0 ]; then
    (cd "$dir" && runuser -u nobody -- "$bin/$prog" "$@")
  else
    (cd "$dir" && "$bin/$prog" "$@")
  fi
}

case $cmd in
start)
  stop # a server a broken run left behind
  dir=$(mktemp -d /tmp/grainpack-pg-XXXXXX)
  [ "$(id -u)" -eq 0 ] && chown nobody "$dir"
  printf '%s\n' "$password" > "$dir/pwfile"
  [ "$(id -u)" -eq 0 ] && chown nobody "$dir/pwfile"
  printf 'dir=%s\n' "$dir" > "$state"
  as_owner "$dir" initdb -D "$dir/data" -U grainpack --pwfile="$dir/pwfile" \
    --auth=scram-sha-256 -E UTF8 --no-locale > "$dir/initdb.log" 2>&1 ||
    { cat "$dir/initdb.log" >&2; exit 1; }
  rm -f "$dir/pwfile"
  # fsync off (GP_PG_FSYNC=on for a benchmark): a test server's data need not survive a
  # power cut, and CI's disk is slow;
  # max_connections: three daemons with their pools, and the tests' own connections
  as_owner "$dir" pg_ctl -D "$dir/data" -l "$dir/server.log" -w -t 60 \
    -o "-k $dir -c listen_addresses= -c fsync=${GP_PG_FSYNC:-off} -c max_connections=200" start > /dev/null ||
    { cat "$dir/server.log" >&2; exit 1; }
  printf 'uri=postgresql://grainpack@/postgres?host=%s\n' "$dir" >> "$state"
  ;;
stop)
  stop
  ;;
*)
  echo "usage: $0 start|stop STATE" >&2
  exit 2
  ;;
esac
