#!/bin/sh
# tests/browser/run.sh — the playground page in Debian's chromium (headless), driven by
# puppeteer-core (tests/browser/package.json; `npm ci` here when node_modules is missing).
# Starts its own umbrad on loopback (ephemeral port); origin.test.js then calls it from pages of
# other origins. Ends with "N passed, N failed". Without chromium or node the suite says so and
# counts nothing (tests/run.sh runs it only when chromium is installed). Env: BUILD, SHARED;
# SHOT=FILE also saves a screenshot.
BUILD=${BUILD:-build}
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
dir=$(dirname "$0")
if [ ! -x "$CHROMIUM" ] || ! command -v node >/dev/null 2>&1; then
	echo "# skipped: needs $CHROMIUM and node (deploy/install-deps.sh installs them)"
	echo "0 passed, 0 failed"
	exit 0
fi
. "$dir/../util/node_suite.sh"
node_tooling puppeteer-core puppeteer-core/package.json
# --max-rss 0: no trim between renders, so a repeated render finds its shadow maps cached (the plan says so).
node_start_umbrad "$T/port" "$T/umbrad.log" --workers 2 --max-rss 0
# The bench examples are in the page when the build found them (Makefile: BENCH_JSON).
BENCH=""
[ -f "${SHARED:-../shared}/bench/thumb-512.json" ] && BENCH=1
BENCH=$BENCH UMBRA_URL=$URL CHROMIUM=$CHROMIUM node "$dir/playground.test.js" >"$T/node.out" 2>&1
# Real cross-origin callers: pages of other local origins posting a form and calling fetch(), to
# this daemon (refused) and to one the test starts with --cors-origin (origin.test.js).
UMBRA_URL=$URL UMBRAD="$BUILD/umbrad" DAEMON_PRELOAD="$PRELOAD" T="$T" CHROMIUM=$CHROMIUM \
	node "$dir/origin.test.js" >>"$T/node.out" 2>&1
grep -v -E '^[0-9]+ passed, [0-9]+ failed' "$T/node.out"
pass=0; fail=0
for line in $(grep -E '^[0-9]+ passed, [0-9]+ failed' "$T/node.out" | tr ' ' '_'); do
	p=${line%%_passed*}; f=${line#*passed,_}; f=${f%%_failed*}
	pass=$((pass + p)); fail=$((fail + f))
done
[ "$(grep -cE '^[0-9]+ passed, [0-9]+ failed' "$T/node.out")" = 2 ] || { echo "FAIL - a browser test gave no result line"; fail=$((fail + 1)); }
# The playground can be switched off.
kill "$PID"; wait "$PID" 2>/dev/null; PID=""
LD_PRELOAD="$PRELOAD" "$BUILD/umbrad" --listen 127.0.0.1:0 --port-file "$T/port2" --workers 1 --no-playground 2>"$T/umbrad2.log" &
PID=$!
i=0
while [ ! -s "$T/port2" ] && [ $i -lt 2400 ] && kill -0 "$PID" 2>/dev/null; do sleep 0.1; i=$((i + 1)); done
code=$(curl -s -o /dev/null -w '%{http_code}' --max-time 10 "http://127.0.0.1:$(cat "$T/port2" 2>/dev/null)/")
if [ "$code" = 404 ]; then echo "ok - --no-playground: GET / is 404"; pass=$((pass + 1))
else echo "FAIL - --no-playground: GET / is $code"; fail=$((fail + 1)); fi
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
