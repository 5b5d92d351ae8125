#!/usr/bin/env bash
# demo.sh - the README's main command: installs what is missing (Debian 12), builds, starts
# grainpackd on 127.0.0.1:8080 with its database in data/grainpack.db, submits the report's
# iron nanostructure, waits for it and prints where its SVG is, the daemon's pid and how to
# stop it. The daemon keeps running afterwards.
#
# It says so and exits 1, before building anything, when the port or the database is
# already in use (by a daemon an earlier run left, for instance): the answer would come
# from that one, not from what this run builds. The setup and build output go to demo.log,
# shown only when they fail; the daemon's log goes to grainpackd.log.
set -uo pipefail
cd "$(dirname "$0")/.."

# the daemon's own variables choose another port or data directory
host=127.0.0.1
port=${GRAINPACKD_PORT:-8080}
data=${GRAINPACKD_DATA_DIR:-data}
db=$data/grainpack.db
log=demo.log
daemon_log=grainpackd.log
ready=$data/grainpackd.ready
# how long to wait for the daemon to listen, and for the job (iron packs in milliseconds;
# a first start may migrate the database)
STARTUP_SECONDS=60
JOB_SECONDS=300

say() { printf '%s\n' "$*"; }
refuse() { printf 'demo: %s\n' "$@" >&2; exit 1; }

# The pid and name of the process listening on the port ("" when unknown).
listener() {
  command -v ss > /dev/null || return 0
  ss -Hltnp "sport = :$port" 2>/dev/null | sed -n 's/.*users:(("\([^"]*\)",pid=\([0-9]*\).*/\2 (\1)/p' | head -1
}

# The pids of the processes that hold the database's lock file open (one find over
# /proc: a descriptor is a symbolic link to the file it has open).
lock_holders() {
  local lock
  lock=$(realpath -m "$db.lock")
  find /proc/[0-9]*/fd -maxdepth 1 -lname "$lock" 2> /dev/null | cut -d/ -f3 | sort -un | tr '\n' ' '
}

# ---- refuse when the port or the database is taken, before building anything
if (exec 3<> "/dev/tcp/$host/$port") 2> /dev/null; then
  who=$(listener)
  case $who in
    *grainpackd*) hint="It is a grainpackd, likely left by an earlier run: its jobs are still at http://$host:$port/. Stop it with:  kill ${who%% *}  and run this again." ;;
    ?*) hint="Stop it (kill ${who%% *}) and run this again." ;;
    *) hint="Stop what listens there and run this again." ;;
  esac
  refuse "port $port on $host is already in use${who:+ by pid $who}: this run's grainpackd could not listen there." \
         "$hint" "Nothing was built or started."
fi
if [ -e "$db.lock" ] && ! flock -n "$db.lock" true 2> /dev/null; then
  holders=$(lock_holders)
  refuse "the database $db is in use by another grainpackd${holders:+ (pid ${holders% })}, which holds" \
         "$db.lock: a second daemon on the same database refuses to start." \
         "Stop that one${holders:+ (kill ${holders% })} and run this again. Nothing was built or started."
fi

# ---- setup and build, their output to the log
: > "$log"
start=$SECONDS
say "demo: installing what is missing and building (output in $log)..."
if ! { bash .ci/setup && cmake -S . -B build -DCMAKE_BUILD_TYPE=Release &&
       cmake --build build -j"$(nproc)"; } >> "$log" 2>&1; then
  tail -n 40 "$log" >&2
  refuse "the setup or the build failed (the end of $log is above; all of it is in $log)."
fi
say "demo: built in $((SECONDS - start)) s"

# ---- start the daemon, detached from this shell, and wait until it listens
mkdir -p "$data"
rm -f "$ready"
setsid ./build/server/grainpackd --host "$host" --port "$port" --data-dir "$data" --ready-file "$ready" \
  < /dev/null >> "$daemon_log" 2>&1 &
pid=$!
deadline=$((SECONDS + STARTUP_SECONDS))
until [ -s "$ready" ]; do
  if ! kill -0 "$pid" 2> /dev/null; then
    tail -n 5 "$daemon_log" >&2
    refuse "grainpackd exited before it listened (the end of $daemon_log is above)."
  fi
  if [ "$SECONDS" -ge "$deadline" ]; then
    kill "$pid"
    refuse "grainpackd did not listen within $STARTUP_SECONDS s; stopped it (see $daemon_log)."
  fi
  sleep 0.1
done
base=http://$host:$port
say "demo: grainpackd is running: pid $pid, $base (database $db, log $daemon_log)"

# ---- submit the iron case and wait for it
job=$(curl -sS -f -o /dev/null -w '%header{location}' -H 'Content-Type: application/json' \
      --data-binary @examples/iron.json "$base/processes/pack2d/execution") && [ -n "$job" ] ||
  refuse "the submission of examples/iron.json failed; grainpackd (pid $pid) is still running: kill $pid"
say "demo: submitted examples/iron.json as $base$job"
deadline=$((SECONDS + JOB_SECONDS))
status=
while [ "$SECONDS" -lt "$deadline" ]; do
  status=$(curl -sS -f "$base$job?wait=30" | grep -o '"status":"[a-z]*"' | head -1 | cut -d'"' -f4)
  case $status in successful | failed | dismissed) break ;; esac
done
[ "$status" = successful ] ||
  refuse "the job ended '${status:-unknown}': see $base$job; grainpackd (pid $pid) is still running: kill $pid"
stats=$(curl -sS -f "$base$job/statistics")
count=$(printf '%s' "$stats" | grep -o '"count":[0-9]*' | head -1 | cut -d: -f2)
density=$(printf '%s' "$stats" | grep -o '"packing_density":[0-9.]*' | head -1 | cut -d: -f2)
[ -n "$density" ] && density=$(printf '%.4f' "$density")
say "demo: the job is done: ${count:-?} grains, packing density ${density:-?}"
say ""
say "SVG: $base$job/results?f=svg"
say ""
say "grainpackd keeps running (pid $pid; log $daemon_log). Stop it with:  kill $pid"
