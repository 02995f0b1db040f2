#!/bin/sh
# tests/util/suite.sh — the set-up every black-box daemon suite shares (tests/http/*.sh):
# BUILD, SHARED, the daemon binary UMBRAD, START_TIMEOUT, the ASan preloads for daemons, a
# temporary folder $T removed at exit (with every daemon in $PIDS killed), ok/nok/check
# counting and `finish` (the closing "N passed, N failed" line and the suite's status).
# Sourced first: `SUITE=name . tests/util/suite.sh`; tests/http/lib.sh adds the daemon helpers
# (start, stop, post, get, hdr, problem, metric...). A suite may redefine any of them.
BUILD=${BUILD:-build}
SHARED=${SHARED:-../shared}
UMBRAD=${UMBRAD:-$BUILD/umbrad}
START_TIMEOUT=${START_TIMEOUT:-240}
# ASan daemons: the Vulkan loader of Debian 12 (1.3.239) unloads the driver at vkDestroyInstance
# whatever VK_LOADER_DISABLE_DYNAMIC_LIBRARY_UNLOADING says, so LeakSanitizer sees the driver's
# own leaks as "<unknown module>" and tests/lsan.supp cannot name them. Preloading the driver
# (after the ASan runtime, which must come first) keeps it mapped. Daemons only: curl and
# python3 run without it.
DAEMON_PRELOAD=""
asan_rt=$(ldd "$UMBRAD" 2>/dev/null | awk '/libasan/ { print $3; exit }')
if [ -n "$asan_rt" ]; then
	for lvp in /usr/lib/*/libvulkan_lvp.so /usr/lib64/libvulkan_lvp.so; do
		[ -f "$lvp" ] && DAEMON_PRELOAD="$asan_rt $lvp" && break
	done
fi

T=$(mktemp -d "${TMPDIR:-/tmp}/umbra-${SUITE:-http}.XXXXXX")
pass=0
fail=0
PIDS=""
PID=""

ok() { echo "ok - $1"; pass=$((pass + 1)); }
nok() { echo "FAIL - $1${2:+: $2}"; fail=$((fail + 1)); }
# check NAME CMD...: ok when CMD succeeds.
check() { n=$1; shift; if "$@"; then ok "$n"; else nok "$n"; fi; }

cleanup() {
	for p in $PIDS; do kill -9 "$p" 2>/dev/null; done
	rm -rf "$T"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

# finish: the closing line every suite prints, and its status.
finish() {
	echo "$pass passed, $fail failed"
	[ "$fail" -eq 0 ]
}

if [ ! -x "$UMBRAD" ]; then
	nok "daemon binary" "$UMBRAD not built"
	finish
	exit 1
fi
