#!/bin/sh
# tests/fuzz/run.sh — the fuzz suite of make test: every libFuzzer target runs briefly (its
# seeds, then mutations) and counts as one test. Last line: "N passed, N failed".
#
# Conventions (tests/fuzz/long.sh and make fuzz follow them too):
#   tests/fuzz/fuzz_NAME.c        a target (make fuzz builds it to $FUZZ_BUILD/fuzz_NAME)
#   tests/fuzz/corpus/fuzz_NAME/  its seeds (committed; new inputs never go back there)
#   tests/fuzz/fuzz_NAME.dict     optional libFuzzer dictionary
#   tests/fuzz/fuzz_NAME.options  optional extra libFuzzer flags, one line (e.g. -max_len=65536)
#
# Env: FUZZ_BUILD (build/fuzz), FUZZ_RUNS (executions per target, default 20000),
# FUZZ_SECONDS (a cap per target so a slow target cannot hold up make test, default 5).
# Runs use -seed=1, so a failure reproduces; its input is kept in $FUZZ_BUILD/artifacts/NAME/.
FUZZ_BUILD=${FUZZ_BUILD:-build/fuzz}
FUZZ_RUNS=${FUZZ_RUNS:-20000}
FUZZ_SECONDS=${FUZZ_SECONDS:-5}
dir=$(dirname "$0")
pass=0; fail=0
# A sanitizer report must end the run with a failure, whatever the caller's *SAN_OPTIONS say.
unset ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS LD_PRELOAD
for src in "$dir"/fuzz_*.c; do
	[ -f "$src" ] || continue
	name=$(basename "$src" .c)
	bin=$FUZZ_BUILD/$name
	if [ ! -x "$bin" ]; then
		echo "FAIL - $name: $bin is not built (make fuzz)"
		fail=$((fail + 1)); continue
	fi
	art=$FUZZ_BUILD/artifacts/$name
	work=$(mktemp -d)
	mkdir -p "$art"
	set -- -seed=1 -runs="$FUZZ_RUNS" -max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048 \
	       -print_final_stats=1 -artifact_prefix="$art/"
	[ -f "$dir/$name.dict" ] && set -- "$@" -dict="$dir/$name.dict"
	# shellcheck disable=SC2046
	[ -f "$dir/$name.options" ] && set -- "$@" $(cat "$dir/$name.options")
	set -- "$@" "$work"
	[ -d "$dir/corpus/$name" ] && set -- "$@" "$dir/corpus/$name"
	"$bin" "$@" >"$work.log" 2>&1
	rc=$?
	runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work.log" | tail -n 1)
	if [ "$rc" -eq 0 ]; then
		echo "ok - $name (${runs:-?} executions)"
		pass=$((pass + 1))
	else
		echo "FAIL - $name: exited $rc; the input is in $art/ (tail of the log follows)"
		tail -n 40 "$work.log"
		fail=$((fail + 1))
	fi
	rm -rf "$work" "$work.log"
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
