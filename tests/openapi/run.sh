#!/bin/sh
# tests/openapi/run.sh — api/openapi.yaml under two linters nobody here wrote: Redocly CLI
# (its recommended rules) and Spectral (spectral:oas, tests/openapi/spectral.yaml), both test
# tooling of tests/browser/package.json (`npm ci` there when missing). A lint error fails the
# suite; warnings are printed as a count (Redocly's example checks do not follow the scene
# schema's unevaluatedProperties through if/then: tests/schema/ checks those with ajv against
# the daemon). Ends with "N passed, N failed"; without node the suite says so and counts nothing.
BUILD=${BUILD:-build}
dir=$(dirname "$0")
. "$dir/../util/node_suite.sh"
node_tooling "redocly, spectral" @stoplight/spectral-cli/package.json
[ -f "$TOOLING/node_modules/@redocly/cli/package.json" ] || node_tooling redocly @redocly/cli/package.json
pass=0; fail=0
bin="$TOOLING/node_modules/.bin"
if "$bin/redocly" lint --format=summary api/openapi.yaml >"$T/redocly.out" 2>&1; then
	echo "ok - redocly lint: 0 errors ($(grep -c '^warning' "$T/redocly.out") kinds of warning)"; pass=$((pass + 1))
else
	sed 's/^/# /' "$T/redocly.out" | grep -v '^# *$' | tail -n 30
	echo "FAIL - redocly lint api/openapi.yaml"; fail=$((fail + 1))
fi
if "$bin/spectral" lint --ruleset "$dir/spectral.yaml" --fail-severity error api/openapi.yaml >"$T/spectral.out" 2>&1; then
	echo "ok - spectral lint (spectral:oas): 0 errors"; pass=$((pass + 1))
else
	sed 's/^/# /' "$T/spectral.out" | tail -n 30
	echo "FAIL - spectral lint api/openapi.yaml"; fail=$((fail + 1))
fi
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
