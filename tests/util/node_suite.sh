#!/bin/sh
# tests/util/node_suite.sh — what the suites driven by node share (tests/browser/run.sh,
# tests/schema/run.sh): the test tooling of tests/browser/package.json (`npm ci` there when
# `needs` is missing), a temporary folder $T removed at exit with the daemon $PID killed, the
# ASan preloads for daemons (PRELOAD), and node_start_umbrad. Sourced after setting BUILD:
#   . tests/util/node_suite.sh
#   node_tooling NAME FILE     skips the suite (exit 0, "0 passed, 0 failed") without node;
#                              runs npm ci when FILE (under node_modules/) is missing
#   node_start_umbrad PORTFILE LOG ARGS...   starts $BUILD/umbrad on a free loopback port,
#                              waits for /readyz (PID, URL set); fails the suite if it never is
TOOLING=$(dirname "$0")/../browser

node_tooling() {
	if ! command -v node >/dev/null 2>&1; then
		echo "# skipped: needs node (deploy/install-deps.sh installs it)"
		echo "0 passed, 0 failed"
		exit 0
	fi
	if [ ! -f "$TOOLING/node_modules/$2" ]; then
		echo "# npm ci in tests/browser ($1, test tooling only)"
		if ! (cd "$TOOLING" && npm ci --no-audit --no-fund >/dev/null 2>&1); then
			echo "FAIL - npm ci in tests/browser"
			echo "0 passed, 1 failed"
			exit 1
		fi
	fi
}

T=$(mktemp -d "${TMPDIR:-/tmp}/umbra-node.XXXXXX")
PID=""
node_cleanup() { [ -n "$PID" ] && kill "$PID" 2>/dev/null && wait "$PID" 2>/dev/null; rm -rf "$T"; }
trap node_cleanup EXIT
trap 'exit 1' INT TERM
# ASan builds: the daemon needs the driver preloaded after the ASan runtime (tests/run.sh).
PRELOAD=""
asan_rt=$(ldd "$BUILD/umbrad" 2>/dev/null | awk '/libasan/ { print $3; exit }')
if [ -n "$asan_rt" ]; then
	for lvp in /usr/lib/*/libvulkan_lvp.so /usr/lib64/libvulkan_lvp.so; do
		[ -f "$lvp" ] && PRELOAD="$asan_rt $lvp" && break
	done
fi

node_start_umbrad() {
	portfile=$1; log=$2; shift 2
	LD_PRELOAD="$PRELOAD" "$BUILD/umbrad" --listen 127.0.0.1:0 --port-file "$portfile" "$@" 2>"$log" &
	PID=$!
	i=0
	while :; do
		if [ -s "$portfile" ] && curl -sf -o /dev/null --max-time 5 "http://127.0.0.1:$(cat "$portfile")/readyz"; then break; fi
		i=$((i + 1))
		if [ $i -gt 2400 ] || ! kill -0 "$PID" 2>/dev/null; then
			echo "FAIL - umbrad did not become ready"; tail -n 20 "$log" | sed 's/^/# /'
			echo "0 passed, 1 failed"
			exit 1
		fi
		sleep 0.1
	done
	URL="http://127.0.0.1:$(cat "$portfile")"
}
