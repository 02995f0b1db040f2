#!/bin/sh
# tests/clients/run.sh — the clients of clients/ (Python, standard library; Node, built-in
# fetch) against a real umbrad on loopback (ephemeral port) and fake servers of their own
# (tests/clients/test_python.py, test_node.mjs). Ends with "N passed, N failed"; without node the
# Node half says so and counts nothing. Env: BUILD.
SUITE=clients . tests/http/lib.sh
start clients --workers 2 --no-playground || { finish; exit 1; }
run_half() { # NAME CMD...: its ok/FAIL lines, its counts added
	half=$1; shift
	"$@" >"$T/$half.out" 2>&1
	grep -v -E '^[0-9]+ passed, [0-9]+ failed' "$T/$half.out"
	line=$(grep -E '^[0-9]+ passed, [0-9]+ failed' "$T/$half.out" | tail -n 1)
	if [ -z "$line" ]; then nok "$half: no result line"; return; fi
	p=${line%% passed*}; f=${line#*passed, }; f=${f%% failed*}
	pass=$((pass + p)); fail=$((fail + f))
}
run_half python python3 tests/clients/test_python.py "$URL"
if command -v node >/dev/null 2>&1; then run_half node node tests/clients/test_node.mjs "$URL"
else echo "# skipped: the Node client needs node"; fi
finish
