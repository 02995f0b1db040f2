#!/bin/sh
# tests/http/soak.sh [N] — N mixed requests (default 10000; SOAK_N also sets it) against one
# $BUILD/umbrad on 127.0.0.1 (ephemeral port), with its RSS and open descriptors sampled
# (tests/http/soak.py says what is sent and what is checked). `make soak` runs 10,000;
# tests/run.sh runs 1,000 (300 under ASan, whose quarantine holds freed memory: the RSS margin
# is wider there and LeakSanitizer checks leaks at exit instead). Bounded: every request has a
# timeout and the whole run is killed after SOAK_LIMIT_S (default 1800) seconds.
# Last line: "N passed, N failed".
BUILD=${BUILD:-build}
UMBRAD=${UMBRAD:-$BUILD/umbrad}
N=${1:-${SOAK_N:-10000}}
START_TIMEOUT=${START_TIMEOUT:-240}
DAEMON_PRELOAD=""
asan_rt=$(ldd "$UMBRAD" 2>/dev/null | awk '/libasan/ { print $3; exit }')
if [ -n "$asan_rt" ]; then
	[ "$N" -gt 300 ] && N=300
	export SOAK_RSS_MARGIN_KB=${SOAK_RSS_MARGIN_KB:-307200}
	for lvp in /usr/lib/*/libvulkan_lvp.so /usr/lib64/libvulkan_lvp.so; do
		[ -f "$lvp" ] && DAEMON_PRELOAD="$asan_rt $lvp" && break
	done
fi
T=$(mktemp -d "${TMPDIR:-/tmp}/umbra-soak.XXXXXX")
PID=""
cleanup() { [ -n "$PID" ] && kill -9 "$PID" 2>/dev/null; rm -rf "$T"; }
trap cleanup EXIT
trap 'exit 1' INT TERM
pass=0; fail=0
finish() { echo "$pass passed, $fail failed"; [ "$fail" -eq 0 ]; exit $?; }

LD_PRELOAD="$DAEMON_PRELOAD" "$UMBRAD" --listen 127.0.0.1:0 --port-file "$T/port" --queue 64 2>"$T/log" &
PID=$!
i=0
while :; do
	if [ -s "$T/port" ] && [ "$(curl -s -o /dev/null -w '%{http_code}' --max-time 5 "http://127.0.0.1:$(cat "$T/port")/readyz")" = 200 ]; then
		break
	fi
	i=$((i + 1))
	if [ $i -gt $((START_TIMEOUT * 10)) ] || ! kill -0 "$PID" 2>/dev/null; then
		echo "FAIL - soak daemon starts"; tail -n 20 "$T/log" | sed 's/^/# /'
		fail=1; finish
	fi
	sleep 0.1
done
echo "# soak: $N requests against pid $PID"
timeout "${SOAK_LIMIT_S:-1800}" python3 tests/http/soak.py "$(cat "$T/port")" "$PID" "$N" "$T" >"$T/py.out" 2>&1
rc=$?
sed -n '/passed, .* failed$/!p' "$T/py.out"
line=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$T/py.out" | tail -n 1)
if [ -z "$line" ]; then
	echo "FAIL - soak ran to its end (exit $rc)"; fail=$((fail + 1))
else
	pass=$((pass + ${line%% passed*})); f=${line#*passed, }; fail=$((fail + ${f%% failed*}))
fi
if kill -0 "$PID" 2>/dev/null; then echo "ok - soak daemon alive at the end"; pass=$((pass + 1)); else
	echo "FAIL - soak daemon alive at the end"; fail=$((fail + 1)); tail -n 20 "$T/log" | sed 's/^/# /'
fi
kill -TERM "$PID" 2>/dev/null
wait "$PID"; rc=$?
PID=""
if [ "$rc" -eq 0 ]; then echo "ok - soak daemon exits 0 after SIGTERM"; pass=$((pass + 1)); else
	echo "FAIL - soak daemon exits 0 after SIGTERM (exit $rc)"; fail=$((fail + 1))
	grep -v ' info ' "$T/log" | tail -n 20 | sed 's/^/# /'
fi
grep -c ' warn ' "$T/log" | sed 's/^/# warnings in the daemon log: /'
finish
