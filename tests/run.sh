#!/bin/sh
# tests/run.sh — runs every test suite and ends with one line "N passed, N failed".
# Env: BUILD (build dir), SHARED (../shared), ASAN=1 under make test-asan.
# Each suite prints "N passed, N failed" as its last line; this script adds them up.
BUILD=${BUILD:-build}
SHARED=${SHARED:-../shared}
export BUILD SHARED
# Any validation-layer message fails a render test (the renderer counts them).
export UMBRA_VALIDATION=1
if [ -n "${ASAN:-}" ]; then
	export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:detect_odr_violation=0"
	export LSAN_OPTIONS="suppressions=$(pwd)/tests/lsan.supp:print_suppressions=0"
	export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
	# Keep the Vulkan driver mapped at exit so its leaks can be attributed (tests/lsan.supp).
	export VK_LOADER_DISABLE_DYNAMIC_LIBRARY_UNLOADING=1
fi
total_pass=0; total_fail=0
run_suite() {
	name=$1; shift
	echo "== $name"
	log=$(mktemp)
	"$@" >"$log" 2>&1
	rc=$?
	cat "$log"
	line=$(grep -E '^[0-9]+ passed, [0-9]+ failed' "$log" | tail -n 1)
	if [ -z "$line" ]; then
		echo "FAIL - $name: exited $rc without a result line"
		total_fail=$((total_fail + 1))
	else
		p=${line%% passed*}; f=${line#*passed, }; f=${f%% failed*}
		total_pass=$((total_pass + p)); total_fail=$((total_fail + f))
		if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
			echo "FAIL - $name: exited $rc (sanitizer report?)"
			total_fail=$((total_fail + 1))
		fi
	fi
	rm -f "$log"
}
# Under ASan the Vulkan loader (1.3.239 ignores VK_LOADER_DISABLE_DYNAMIC_LIBRARY_UNLOADING)
# unloads lavapipe before LeakSanitizer runs, so the driver's own leaks show as "<unknown
# module>" that tests/lsan.supp cannot name. Preloading the driver (after the ASan runtime)
# keeps it mapped. Only for our test binaries, not for the shell tools the suites call.
PRELOAD=""
asan_rt=$(ldd "$BUILD/tests/unit_tests" 2>/dev/null | awk '/libasan/ { print $3; exit }')
if [ -n "$asan_rt" ]; then
	for lvp in /usr/lib/*/libvulkan_lvp.so /usr/lib64/libvulkan_lvp.so; do
		[ -f "$lvp" ] && PRELOAD="$asan_rt $lvp" && break
	done
fi
run_suite unit env LD_PRELOAD="$PRELOAD" "$BUILD/tests/unit_tests"
[ -x "$BUILD/tests/gpu_tests" ] && run_suite gpu env LD_PRELOAD="$PRELOAD" "$BUILD/tests/gpu_tests"
[ -f tests/http/run.sh ] && [ -x "$BUILD/umbrad" ] && run_suite http sh tests/http/run.sh
[ -x "$BUILD/umbrad" ] && run_suite http-limits sh tests/http/limits.sh
[ -x "$BUILD/umbrad" ] && run_suite http-sandbox sh tests/http/sandbox.sh
[ -x "$BUILD/umbrad" ] && run_suite http-imports sh tests/http/imports.sh
[ -x "$BUILD/umbrad" ] && run_suite http-assets sh tests/http/assets.sh
[ -x "$BUILD/umbrad" ] && run_suite http-origin sh tests/http/origin.sh
[ -x "$BUILD/umbrad" ] && run_suite clients sh tests/clients/run.sh
# Every command of README.md run as written, against a real umbrad (tests/readme/check.py).
[ -x "$BUILD/umbrad" ] && [ -x "$BUILD/umbra-render" ] && run_suite readme sh tests/readme/run.sh
[ -z "${ASAN:-}" ] && run_suite deploy sh deploy/check.sh
command -v haproxy >/dev/null && [ -x "$BUILD/umbrad" ] && run_suite cluster env DAEMON_PRELOAD="$PRELOAD" python3 tests/cluster/test_cluster.py
# umbra-render thumb --server: the farm on three daemons behind HAProxy (and a fake server).
command -v haproxy >/dev/null && [ -x "$BUILD/umbrad" ] && [ -x "$BUILD/umbra-render" ] &&
	run_suite farm-remote env DAEMON_PRELOAD="$PRELOAD" python3 tests/cluster/test_farm.py
[ -x "$BUILD/umbrad" ] && run_suite http-thumbnail sh tests/http/thumbnail.sh
[ -x "$BUILD/umbrad" ] && run_suite http-explain sh tests/http/explain.sh
# Cacheable renders (POST /v1/renders, GET /v1/renders/{hash}), and nginx in front when installed.
[ -x "$BUILD/umbrad" ] && run_suite http-cache sh tests/http/cache.sh
[ -x "$BUILD/umbra-render" ] && run_suite cli sh tests/cli/run.sh
# api/scene.schema.json against the daemon (ajv from tests/browser's tooling; skipped without node).
[ -x "$BUILD/umbrad" ] && run_suite schema sh tests/schema/run.sh
run_suite openapi sh tests/openapi/run.sh
# The playground in a real browser, when Debian's chromium is installed (install-deps does).
[ -x "$BUILD/umbrad" ] && [ -x /usr/bin/chromium ] && run_suite browser sh tests/browser/run.sh
# libFuzzer targets, a few seconds each (make test builds them into FUZZ_BUILD).
[ -n "${FUZZ_BUILD:-}" ] && run_suite fuzz sh tests/fuzz/run.sh
[ -f tests/http/conn.sh ] && [ -x "$BUILD/umbrad" ] && run_suite conn sh tests/http/conn.sh
# A short soak (make soak runs 10,000); under ASan soak.sh lowers it to 300.
[ -f tests/http/soak.sh ] && [ -x "$BUILD/umbrad" ] && run_suite soak sh tests/http/soak.sh "${SOAK_N:-1000}"
[ -f tests/http/faults.sh ] && [ -x "$BUILD/umbrad" ] && run_suite faults sh tests/http/faults.sh
echo "$total_pass passed, $total_fail failed"
[ "$total_fail" -eq 0 ]
