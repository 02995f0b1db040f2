#!/bin/sh
# tests/http/conn.sh — connection limits, timeouts and HTTP framing of $BUILD/umbrad
# (tests/http/conn.py does the talking). Loopback only: the daemon listens on 127.0.0.1 with an
# ephemeral port. Prints "ok - x" / "FAIL - x" per test and, last, "N passed, N failed".
# Env: BUILD (build dir), UMBRA_VALIDATION (tests/run.sh sets 1).
SUITE=conn . tests/util/suite.sh
# This suite's finish also exits (it is called on fatal set-up failures too).
finish() { echo "$pass passed, $fail failed"; [ "$fail" -eq 0 ]; exit $?; }

# ---- flags ----
"$UMBRAD" --help >"$T/help" 2>&1
for f in --max-connections --max-connections-per-ip --max-connections-per-range --idle-timeout --header-timeout; do
	if grep -q -- "$f " "$T/help"; then ok "--help lists $f"; else nok "--help lists $f"; fi
done
# (bounded, on an ephemeral port: a daemon that accepted the value would otherwise keep running)
UMBRA_MAX_CONNECTIONS_PER_IP=many timeout 20 "$UMBRAD" --listen 127.0.0.1:0 >/dev/null 2>&1
[ $? = 2 ] && ok "bad UMBRA_MAX_CONNECTIONS_PER_IP exits 2" || nok "bad UMBRA_MAX_CONNECTIONS_PER_IP exits 2"
timeout 20 "$UMBRAD" --listen 127.0.0.1:0 --max-connections-per-range -1 >/dev/null 2>&1
[ $? = 2 ] && ok "bad --max-connections-per-range exits 2" || nok "bad --max-connections-per-range exits 2"

# ---- daemons ----
cat >"$T/scene.json" <<'EOF'
{"width": 64, "height": 64,
 "camera": {"type": "perspective", "position": [4, 3, 4], "target": [0, 0.8, 0], "up": [0, 1, 0], "fov_y": 40},
 "objects": [{"shape": "plane", "size": [10, 10]}, {"shape": "sphere", "radius": 1, "transform": {"translation": [0, 1, 0]}}],
 "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3], "intensity": 3}]}
EOF
# start NAME FLAGS...: a daemon on an ephemeral port; sets PID and PORT once /readyz is 200.
start() {
	name=$1; shift
	LD_PRELOAD="$DAEMON_PRELOAD" "$UMBRAD" --listen 127.0.0.1:0 --port-file "$T/$name.port" --workers 1 "$@" 2>"$T/$name.log" &
	PID=$!
	PIDS="$PIDS $PID"
	i=0
	while :; do
		if [ -s "$T/$name.port" ]; then
			PORT=$(cat "$T/$name.port")
			[ "$(curl -s -o /dev/null -w '%{http_code}' --max-time 5 "http://127.0.0.1:$PORT/readyz")" = 200 ] && return 0
		fi
		i=$((i + 1))
		if [ $i -gt $((START_TIMEOUT * 10)) ] || ! kill -0 "$PID" 2>/dev/null; then
			nok "$name daemon starts" "log:"; tail -n 20 "$T/$name.log" | sed 's/^/# /'
			return 1
		fi
		sleep 0.1
	done
}
# run_py NAME ARGS...: conn.py's lines, its counts added to ours.
run_py() {
	python3 tests/http/conn.py "$@" >"$T/py.out" 2>&1
	sed -n '/passed, .* failed$/!p' "$T/py.out"
	line=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$T/py.out" | tail -n 1)
	if [ -z "$line" ]; then
		nok "conn.py $1 ran to its end"
	else
		pass=$((pass + ${line%% passed*})); f=${line#*passed, }; fail=$((fail + ${f%% failed*}))
	fi
}
# stop NAME: the daemon must be alive, then exit 0 on SIGTERM.
stop() {
	kill -0 "$PID" 2>/dev/null && ok "$1 daemon alive after its tests" || nok "$1 daemon alive after its tests"
	kill -TERM "$PID" 2>/dev/null
	wait "$PID"; rc=$?
	PID=""
	if [ "$rc" -eq 0 ]; then ok "$1 daemon exits 0 after SIGTERM"; else
		nok "$1 daemon exits 0 after SIGTERM" "exit $rc"; grep -v ' info ' "$T/$1.log" | tail -n 20 | sed 's/^/# /'
	fi
}

# Framing and timeouts (the header timeout set by its variable, to test that too).
if UMBRA_HEADER_TIMEOUT=1 start framing --idle-timeout 8; then
	run_py framing "$PORT" "$T/scene.json" "$PID"
	stop framing
fi
# Too few descriptors for --max-connections: the limit is lowered (with a warning) rather than
# accept() failing for every client once the descriptors run out.
UMBRAD_REAL=$UMBRAD
UMBRAD="$T/umbrad-200fds"
printf '#!/bin/sh\nulimit -n 200 || exit 1\nexec "%s" "$@"\n' "$UMBRAD_REAL" >"$UMBRAD"
chmod +x "$UMBRAD"
if start fdlimit; then
	if grep -q -- '--max-connections 1024 lowered to 136: the open-file limit is 200' "$T/fdlimit.log"; then
		ok "open-file limit 200: --max-connections lowered to 136, with a warning"
	else
		nok "open-file limit 200: --max-connections lowered to 136, with a warning"; grep -i 'connections\|limit' "$T/fdlimit.log" | sed 's/^/# /'
	fi
	stop fdlimit
fi
UMBRAD=$UMBRAD_REAL
# Share per address range: one /24 at its share, another served.
if start ranges --max-connections 32 --max-connections-per-range 4; then
	run_py ranges "$PORT" "$PID"
	stop ranges
fi
# One client's idle sockets against the default limits.
if start hogs; then
	run_py hogs "$PORT" "$PID"
	stop hogs
fi
finish
