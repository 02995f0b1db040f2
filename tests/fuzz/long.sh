#!/bin/sh
# tests/fuzz/long.sh RUNS [NAME...] — the long run behind make fuzz-long: each target (all of
# tests/fuzz/fuzz_*.c, or the NAMEs given) runs RUNS executions, one target at a time, then one
# table: target, executions, exec/s, crashes, timeouts, seconds. libFuzzer stops at the first
# crash, leak, out-of-memory or timeout; its input goes to $FUZZ_BUILD/artifacts/NAME/ and the
# row shows what stopped it. Same conventions as tests/fuzz/run.sh (corpus, .dict, .options).
# New inputs go to $FUZZ_BUILD/corpus/NAME/ (kept between runs, never committed by this).
FUZZ_BUILD=${FUZZ_BUILD:-build/fuzz}
RUNS=${1:-1000000}
[ $# -gt 0 ] && shift
dir=$(dirname "$0")
unset ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS LD_PRELOAD
if [ $# -eq 0 ]; then
	for src in "$dir"/fuzz_*.c; do set -- "$@" "$(basename "$src" .c)"; done
fi
table=$(mktemp)
printf '%-22s %12s %10s %8s %9s %8s  %s\n' target executions exec/s crashes timeouts seconds stopped-by >"$table"
bad=0
for name in "$@"; do
	bin=$FUZZ_BUILD/$name
	art=$FUZZ_BUILD/artifacts/$name
	corpus=$FUZZ_BUILD/corpus/$name
	log=$FUZZ_BUILD/$name.long.log
	mkdir -p "$art" "$corpus"
	rm -f "$art"/crash-* "$art"/leak-* "$art"/timeout-* "$art"/oom-* "$art"/slow-unit-*
	set -- -runs="$RUNS" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$art/"
	[ -f "$dir/$name.dict" ] && set -- "$@" -dict="$dir/$name.dict"
	# shellcheck disable=SC2046
	[ -f "$dir/$name.options" ] && set -- "$@" $(cat "$dir/$name.options")
	set -- "$@" "$corpus"
	[ -d "$dir/corpus/$name" ] && set -- "$@" "$dir/corpus/$name"
	echo "== $name: $bin $*" >&2
	t0=$(date +%s)
	"$bin" "$@" >"$log" 2>&1
	rc=$?
	secs=$(( $(date +%s) - t0 ))
	execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
	eps=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
	crashes=$(find "$art" -name 'crash-*' -o -name 'leak-*' -o -name 'oom-*' | wc -l)
	timeouts=$(find "$art" -name 'timeout-*' | wc -l)
	stopped=""
	[ "$rc" -ne 0 ] && stopped="exit $rc: $(grep -m1 -E 'ERROR: (libFuzzer|AddressSanitizer|LeakSanitizer)|runtime error' "$log" | cut -c1-80)"
	[ "$rc" -ne 0 ] && bad=$((bad + 1))
	printf '%-22s %12s %10s %8s %9s %8s  %s\n' "$name" "${execs:-?}" "${eps:-?}" "$crashes" "$timeouts" \
	       "$secs" "$stopped" >>"$table"
done
cat "$table"
rm -f "$table"
[ "$bad" -eq 0 ]
