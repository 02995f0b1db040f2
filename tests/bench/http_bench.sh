#!/bin/sh
# tests/bench/http_bench.sh — HTTP benchmark of umbrad over loopback: starts $BUILD/umbrad on an
# ephemeral port, waits for /readyz, runs $BUILD/tests/http_bench (built here from
# tests/bench/http_bench.c when missing) on the $SHARED/bench scenes at concurrency 1, 2, 4, 8,
# prints the daemon's RSS when ready and after the rows, then stops it with SIGTERM. Numbers only;
# nothing is asserted.
# Env: BUILD, SHARED, HTTP_BENCH_CONC (1,2,4,8), HTTP_BENCH_REQUESTS (16), HTTP_BENCH_WARMUP (1),
#      HTTP_BENCH_SECONDS (15 per row), HTTP_BENCH_SCENES (default: every $SHARED/bench/*.json).
set -eu
BUILD=${BUILD:-build}
SHARED=${SHARED:-../shared}
BENCH=$BUILD/tests/http_bench
if [ ! -x "$BENCH" ]; then
	mkdir -p "$BUILD/tests"
	${CC:-cc} -O2 -std=c11 -D_GNU_SOURCE -Wall -Wextra -pthread -o "$BENCH" tests/bench/http_bench.c
fi
tmp=$(mktemp -d)
pid=""
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
"$BUILD/umbrad" --listen 127.0.0.1:0 --port-file "$tmp/port" --queue 256 --log-format json 2>"$tmp/log" &
pid=$!
i=0
until [ -s "$tmp/port" ] && curl -sf -o /dev/null "http://127.0.0.1:$(cat "$tmp/port")/readyz"; do
	i=$((i + 1))
	if [ $i -gt 1200 ] || ! kill -0 "$pid" 2>/dev/null; then
		echo "umbrad did not become ready:" >&2; tail -n 20 "$tmp/log" >&2; exit 1
	fi
	sleep 0.1
done
url="http://127.0.0.1:$(cat "$tmp/port")"
# Resident memory of the daemon, warm (ready) and after the rows: tests/bench/ratios.py reads these.
rss() { echo "umbrad RSS $1: $(awk '/^VmRSS/ {print $2}' "/proc/$pid/status") kB, peak $(awk '/^VmHWM/ {print $2}' "/proc/$pid/status") kB"; }
rss ready
echo "umbrad $(curl -s "$url/v1/info" | sed -n 's/.*"device": *"\([^"]*\)".*/device: \1/p'), $(nproc) CPUs"
# shellcheck disable=SC2086
"$BENCH" -c "${HTTP_BENCH_CONC:-1,2,4,8}" -n "${HTTP_BENCH_REQUESTS:-16}" -t "${HTTP_BENCH_SECONDS:-15}" \
	-w "${HTTP_BENCH_WARMUP:-1}" "$url" \
	${HTTP_BENCH_SCENES:-"$SHARED"/bench/*.json} || status=$?
rss after
curl -s "$url/metrics" | grep -E '^umbra_(stage_seconds_(sum|count)|queue_wait_seconds_(sum|count)|shadow_maps_re)' || true
kill -TERM "$pid"
wait "$pid" || { rc=$?; echo "umbrad exited $rc" >&2; exit 1; }
pid=""
exit ${status:-0}
