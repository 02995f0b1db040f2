#!/bin/sh
# tests/schema/run.sh — api/scene.schema.json agrees with the daemon: schema.test.js validates
# every document of corpus.js with ajv (tests/browser/package.json's test tooling; `npm ci`
# there when it is missing) and POSTs it to an umbrad started here on loopback (ephemeral port).
# Ends with "N passed, N failed"; without node the suite says so and counts nothing. Env: BUILD.
BUILD=${BUILD:-build}
dir=$(dirname "$0")
tooling="$dir/../browser"
if ! command -v node >/dev/null 2>&1; then
	echo "# skipped: needs node (deploy/install-deps.sh installs it)"
	echo "0 passed, 0 failed"
	exit 0
fi
if [ ! -f "$tooling/node_modules/ajv/dist/2020.js" ]; then
	echo "# npm ci in tests/browser (ajv, test tooling only)"
	if ! (cd "$tooling" && npm ci --no-audit --no-fund >/dev/null 2>&1); then
		echo "FAIL - npm ci in tests/browser"
		echo "0 passed, 1 failed"
		exit 1
	fi
fi
T=$(mktemp -d "${TMPDIR:-/tmp}/umbra-schema.XXXXXX")
PID=""
cleanup() { [ -n "$PID" ] && kill "$PID" 2>/dev/null && wait "$PID" 2>/dev/null; rm -rf "$T"; }
trap cleanup EXIT
trap 'exit 1' INT TERM
# ASan builds: the daemon needs the driver preloaded after the ASan runtime (tests/run.sh).
PRELOAD=""
asan_rt=$(ldd "$BUILD/umbrad" 2>/dev/null | awk '/libasan/ { print $3; exit }')
if [ -n "$asan_rt" ]; then
	for lvp in /usr/lib/*/libvulkan_lvp.so /usr/lib64/libvulkan_lvp.so; do
		[ -f "$lvp" ] && PRELOAD="$asan_rt $lvp" && break
	done
fi
LD_PRELOAD="$PRELOAD" "$BUILD/umbrad" --listen 127.0.0.1:0 --port-file "$T/port" --workers 2 --no-playground \
	2>"$T/umbrad.log" &
PID=$!
i=0
while :; do
	if [ -s "$T/port" ] && curl -sf -o /dev/null --max-time 5 "http://127.0.0.1:$(cat "$T/port")/readyz"; then break; fi
	i=$((i + 1))
	if [ $i -gt 2400 ] || ! kill -0 "$PID" 2>/dev/null; then
		echo "FAIL - umbrad did not become ready"; tail -n 20 "$T/umbrad.log" | sed 's/^/# /'
		echo "0 passed, 1 failed"
		exit 1
	fi
	sleep 0.1
done
UMBRA_URL="http://127.0.0.1:$(cat "$T/port")" node "$dir/schema.test.js"
