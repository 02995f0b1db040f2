#!/bin/sh
# tests/openapi/run.sh — api/openapi.yaml under two linters nobody here wrote: Redocly CLI
# (its recommended rules) and Spectral (spectral:oas, tests/openapi/spectral.yaml), both test
# tooling of tests/browser/package.json (`npm ci` there when missing). A lint error fails the
# suite; warnings are printed as a count. Redocly checks every example against the scene schema
# (tests/openapi/redocly.yaml: as written, an invalid example is an error), and the suite checks
# that it does: a copy with a box given a radius must fail. Ends with "N passed, N failed";
# without node the suite says so and counts nothing.
BUILD=${BUILD:-build}
dir=$(dirname "$0")
. "$dir/../util/node_suite.sh"
node_tooling "redocly, spectral" @stoplight/spectral-cli/package.json
[ -f "$TOOLING/node_modules/@redocly/cli/package.json" ] || node_tooling redocly @redocly/cli/package.json
pass=0; fail=0
bin="$TOOLING/node_modules/.bin"
redocly() { "$bin/redocly" lint --config "$dir/redocly.yaml" "$@"; }
if redocly --format=summary api/openapi.yaml >"$T/redocly.out" 2>&1; then
	echo "ok - redocly lint: 0 errors, examples valid ($(grep -E '^warning' "$T/redocly.out" | tr '\n' ' '))"; pass=$((pass + 1))
else
	sed 's/^/# /' "$T/redocly.out" | grep -v '^# *$' | tail -n 30
	echo "FAIL - redocly lint api/openapi.yaml"; fail=$((fail + 1))
fi
# The example check is live: a box with a radius (a sphere's member) in MinimalScene is an error.
mkdir -p "$T/api" && cp api/scene.schema.json "$T/api/" &&
	sed '/^    MinimalScene:/,/^    [A-Za-z]*Scene:/ s/^\(          \)- shape: box$/\1- shape: box\n\1  radius: 2/' api/openapi.yaml >"$T/api/openapi.yaml"
if grep -q '  radius: 2' "$T/api/openapi.yaml" && ! redocly "$T/api/openapi.yaml" >"$T/redocly-bad.out" 2>&1 &&
	grep -q 'unevaluated properties `radius`' "$T/redocly-bad.out"; then
	echo "ok - redocly flags an invalid example (a box with a radius)"; pass=$((pass + 1))
else
	sed 's/^/# /' "$T/redocly-bad.out" | tail -n 10
	echo "FAIL - redocly does not flag a box with a radius in an example"; fail=$((fail + 1))
fi
if "$bin/spectral" lint --ruleset "$dir/spectral.yaml" --fail-severity error api/openapi.yaml >"$T/spectral.out" 2>&1; then
	echo "ok - spectral lint (spectral:oas): 0 errors"; pass=$((pass + 1))
else
	sed 's/^/# /' "$T/spectral.out" | tail -n 30
	echo "FAIL - spectral lint api/openapi.yaml"; fail=$((fail + 1))
fi
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
