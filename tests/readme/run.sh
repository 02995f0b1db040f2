#!/bin/sh
# tests/readme/run.sh — every command of README.md, run as a user would run it, against a real
# umbrad on a free loopback port (tests/readme/check.py: how the commands are found, run and
# checked, and the marker convention of the README's code blocks). Ends with "N passed, N
# failed". Env: BUILD, SHARED, ASAN, FUZZ_BUILD.
SUITE=readme . tests/http/lib.sh
start readme --workers 2 || { finish; exit 1; }
echo "# the suite's daemon: $URL"
DAEMON_PRELOAD="$DAEMON_PRELOAD" python3 tests/readme/check.py README.md "$URL" "$T"
