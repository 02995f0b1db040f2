#!/bin/sh
# tests/bench/cpu_ab.sh — CPU time per render of one scene for two or more builds of
# tests/bench, interleaved (A B A B ...) so that each sees the same load. On a shared machine
# with lavapipe the wall medians of `make bench` move by 2x with other jobs; the process's CPU
# time per render moves by ~10 %, which is what an A/B of a shader change needs.
#   CPU per render = (cpu(bench -n N2) - cpu(bench -n N1)) / (N2 - N1)
# so the device start-up, pipeline compilation and the warm-up render cancel out.
# Usage: sh tests/bench/cpu_ab.sh SCENE.json BENCH_A BENCH_B...   (env: N1=1 N2=5 ROUNDS=2)
# Numbers only; nothing is asserted.
set -eu
[ $# -ge 2 ] || { echo "usage: $0 SCENE.json BENCH..." >&2; exit 2; }
scene=$1; shift
n1=${N1:-1}; n2=${N2:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cpu() { # BENCH N -> user+sys seconds
	/usr/bin/time -o "$tmp/t" -f "%U %S" "$1" -n "$2" "$scene" >/dev/null 2>&1
	awk '{print $1 + $2}' "$tmp/t"
}
for r in $(seq "${ROUNDS:-2}"); do
	for b in "$@"; do
		a=$(cpu "$b" "$n1"); c=$(cpu "$b" "$n2")
		awk -v a="$a" -v c="$c" -v n="$((n2 - n1))" -v b="$b" -v s="$(basename "$scene")" -v r="$r" \
			'BEGIN { printf "round %s  %-40s %-24s cpu/render %6.0f ms\n", r, b, s, (c - a) * 1000 / n }'
	done
done
