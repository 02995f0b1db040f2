#!/bin/sh
# tests/http/sandbox.sh — untrusted models against a live umbrad (loopback, ephemeral port):
# a PLY that crashes Assimp and one that makes it loop for ever are answered 400 / 422 with the
# member's pointer while other requests sent at the same time render, /readyz stays 200 and
# SIGTERM drains; a FIFO under --asset-root is a 400 at once. Every input is generated here.
# Prints "ok - x" / "FAIL - x" and, last, "N passed, N failed". Env: BUILD, UMBRAD, ASAN.
# IMPORT_FLAGS="" runs the same checks against a daemon from before the sandbox (no such flag).
IMPORT_FLAGS=${IMPORT_FLAGS---import-timeout-ms 2000}
SUITE=sandbox . tests/util/suite.sh
# This suite's finish also exits (it is called on fatal set-up failures too).
finish() { echo "$pass passed, $fail failed"; [ $fail -eq 0 ]; exit $?; }

# ---- inputs: scenes with an inline model (base64) ----
python3 - "$T" <<'PY'
import base64, json, struct, sys
t = sys.argv[1]
hdr = ("ply\nformat %s 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 2\nproperty list uchar int vertex_indices\n%s\n")
# Misspelled end_header: Assimp 5.2 loops for ever. Damaged binary end_header: it crashes.
hang = (hdr % ("ascii", "end_headr") + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n").encode()
crash = (hdr % ("binary_little_endian", "end_heade")).encode()[:-1] + b"\x8a\n"
crash += struct.pack("<12f", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
crash += struct.pack("<B3i", 3, 0, 1, 2) + struct.pack("<B3i", 3, 0, 2, 3)
good = b"v -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n"
def scene(model):
    return {"width": 64, "height": 64,
            "camera": {"type": "perspective", "position": [4, 3, 4], "target": [0, 0.5, 0], "up": [0, 1, 0], "fov_y": 40},
            "objects": [model, {"shape": "plane", "size": [10, 10]}],
            "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3], "intensity": 3}],
            "output": {"msaa": 1}}
b64 = lambda d: base64.b64encode(d).decode()
docs = {"crash": scene({"shape": "model", "data": b64(crash), "format": "ply"}),
        "hang": scene({"shape": "model", "data": b64(hang)}),
        "good-model": scene({"shape": "model", "data": b64(good), "format": "obj"}),
        "plain": scene({"shape": "sphere", "radius": 1, "transform": {"translation": [0, 1, 0]}}),
        "fifo": scene({"shape": "model", "path": "pipe.obj"})}
for k, v in docs.items():
    json.dump(v, open("%s/%s.json" % (t, k), "w"))
PY
mkdir -p "$T/assets"
mkfifo "$T/assets/pipe.obj"

# ---- helpers ----
start() {
	name=$1; shift
	LD_PRELOAD="$DAEMON_PRELOAD" "$UMBRAD" --listen 127.0.0.1:0 --port-file "$T/$name.port" "$@" 2>"$T/$name.log" &
	PID=$!; PIDS="$PIDS $PID"; i=0
	while [ ! -s "$T/$name.port" ] || [ "$(curl -s -o /dev/null -w '%{http_code}' --max-time 5 \
		"http://127.0.0.1:$(cat "$T/$name.port")/readyz")" != 200 ]; do
		i=$((i + 1))
		if [ $i -gt $((START_TIMEOUT * 10)) ] || ! kill -0 "$PID" 2>/dev/null; then
			nok "start $name" "log:"; tail -n 20 "$T/$name.log" | sed 's/^/# /'; return 1
		fi
		sleep 0.1
	done
	URL="http://127.0.0.1:$(cat "$T/$name.port")"
}
# post NAME SCENE: status code into NAME.code, body NAME.body (in the background with &).
post() {
	curl -s --max-time 60 -o "$T/$1.body" -D "$T/$1.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
		--data-binary "@$T/$2.json" "$URL/v1/render" >"$T/$1.code"
}
code() { cat "$T/$1.code" 2>/dev/null; }
# problem NAME STATUS POINTER
problem() {
	python3 - "$T/$1.body" "$2" "$3" <<'PY'
import json, sys
try:
    d = json.load(open(sys.argv[1]))
except Exception as e:
    print("# not JSON:", e); sys.exit(1)
ok = d.get("status") == int(sys.argv[2]) and d.get("pointer") == sys.argv[3]
if not ok: print("# problem:", json.dumps(d)[:400])
sys.exit(0 if ok else 1)
PY
}

# ---- the daemon: two workers, 2 s import limit ----
start sbx --workers 2 $IMPORT_FLAGS --asset-root "$T/assets" --model-cache 0 || finish
SBX=$PID
check "/v1/info lists the import limits" sh -c "curl -s '$URL/v1/info' | grep -q '\"import_timeout_ms\":2000'"

post crash crash
check "crashing PLY inline: 400" [ "$(code crash)" = 400 ]
check "crashing PLY: problem at /objects/0/data" problem crash 400 /objects/0/data
check "daemon alive after the crash" [ "$(curl -s -o /dev/null -w '%{http_code}' --max-time 5 "$URL/healthz")" = 200 ]

# A hanging PLY, a valid model behind it and a plain render, all at once: only the PLY fails.
post hang hang & p1=$!
sleep 0.3
post good good-model & p2=$!
post plain plain & p3=$!
sleep 0.5
ready=$(curl -s -o /dev/null -w '%{http_code}' --max-time 5 "$URL/readyz")
wait $p1 $p2 $p3
check "hanging PLY: 422 at its time limit" [ "$(code hang)" = 422 ]
check "hanging PLY: problem at /objects/0/data" problem hang 422 /objects/0/data
check "model request sent behind the hanging one: 200" [ "$(code good)" = 200 ]
check "plain render sent with the hanging one: 200" [ "$(code plain)" = 200 ]
check "/readyz 200 while a model import hangs" [ "$ready" = 200 ]

post fifo fifo
check "FIFO under --asset-root: 400 (not blocked)" [ "$(code fifo)" = 400 ]
check "FIFO: problem at /objects/0/path" problem fifo 400 /objects/0/path

# SIGTERM with a hanging import in flight: it is answered (422) and the daemon exits 0.
post hang2 hang & p1=$!
sleep 0.5
helper=$(ps -o pid= --ppid "$SBX" 2>/dev/null | head -n 1 | tr -d ' ')
kill -TERM "$SBX"
wait "$SBX"; rc=$?
wait $p1
check "SIGTERM during a hanging import: in-flight request answered 422" [ "$(code hang2)" = 422 ]
check "SIGTERM during a hanging import: exit 0" [ "$rc" = 0 ]
if [ -n "$helper" ]; then
	i=0; while kill -0 "$helper" 2>/dev/null && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
	check "the importer's fork server ends with the daemon" sh -c "! kill -0 $helper 2>/dev/null"
fi
finish
