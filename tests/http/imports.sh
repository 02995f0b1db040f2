#!/bin/sh
# tests/http/imports.sh — imports never hold a render's thread, and one client's imports do not
# starve another's (issue 29; server/imports.h). A daemon with two workers and two import
# threads; client A (127.0.0.1) sends four models whose import hangs until
# --import-timeout-ms; client B (127.0.0.2) then sends a plain render and a model. Before, A's
# imports held both workers: B's render waited for A's first two time-outs and B's model for
# the last two. The assertions are on the order of the answers, with margins of the import
# time limit (12 s: a loaded CI machine may take seconds over its first pipelines) over a
# 64^2 render. Then the overlap of one model's import with another's render (issue 28).
# Prints "N passed, N failed" last.
. tests/http/lib.sh

python3 - "$T" <<'PY'
import base64, json, sys
t = sys.argv[1]
def scene(model):
    return {"width": 64, "height": 64, "camera": {"position": [4, 3, 4], "target": [0, 0.5, 0]},
            "objects": [model, {"shape": "plane", "size": [10, 10]}],
            "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3]}], "output": {"msaa": 1}}
b64 = lambda d: base64.b64encode(d).decode()
# Misspelled end_header: Assimp 5.2 loops for ever (tests/http/sandbox.sh); a comment line each
# makes them four different models.
for i in range(4):
    hang = ("ply\nformat ascii 1.0\ncomment %d\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_headr\n"
            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n" % i).encode()
    json.dump(scene({"shape": "model", "data": b64(hang)}), open("%s/hang%d.json" % (t, i), "w"))
good = b"v -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n"
json.dump(scene({"shape": "model", "data": b64(good), "format": "obj"}), open(t + "/model.json", "w"))
json.dump(scene({"shape": "sphere", "radius": 1, "transform": {"translation": [0, 1, 0]}}), open(t + "/plain.json", "w"))
# A model in a scene that takes seconds to render (2048^2, a soft sun and four soft spots).
slow = scene({"shape": "model", "data": b64(good), "format": "obj"})
slow.update({"width": 2048, "height": 2048, "output": {"msaa": 4}})
slow["lights"] = [{"type": "directional", "direction": [-0.5, -1, -0.3], "angular_diameter": 3}] + [
    {"type": "spot", "position": [3 * x, 4, 3 * z], "direction": [-3 * x, -4, -3 * z], "radius": 0.2}
    for x, z in ((1, 1), (-1, 1), (1, -1), (-1, -1))]
json.dump(slow, open(t + "/slow.json", "w"))
PY

# send NAME SCENE [CURL ARGS]: in the background; NAME.code, then NAME.done (nanoseconds).
send() {
	sn=$1; sf=$2; shift 2
	(curl -s --max-time 120 -o "$T/$sn.body" -D "$T/$sn.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
		--data-binary "@$T/$sf.json" "$@" "$URL/v1/render" >"$T/$sn.code"; date +%s%N >"$T/$sn.done") &
	SENT="$SENT $!"
}
SENT=
# wait_for FN VALUE: polls /metrics through FN until it says VALUE (at most 60 s).
imports_running() { curl -s --max-time 5 "$URL/metrics" | awk '$1 == "umbra_imports_running" { print $2 }'; }
importing_none_parked() { curl -s --max-time 5 "$URL/metrics" | awk '$1 == "umbra_imports_running" { r = $2 } $1 == "umbra_imports_parked" { p = $2 } END { print r "/" p }'; }
renders_running() { curl -s --max-time 5 "$URL/metrics" | awk '$1 == "umbra_renders_in_flight" { print $2 }'; }
imports_parked() { curl -s --max-time 5 "$URL/metrics" | awk '$1 == "umbra_imports_parked" { print $2 }'; }
wait_for() {
	i=0
	while [ "$($1)" != "$2" ] && [ $i -lt 600 ]; do sleep 0.1; i=$((i + 1)); done
	[ "$($1)" = "$2" ]
}
before() { [ "$(cat "$T/$1.done")" -lt "$(cat "$T/$2.done")" ]; }

if start imp --workers 2 --import-slots 2 --import-timeout-ms 12000; then
	send a0 hang0; send a1 hang1
	check "client A's first two imports both run (no other client waits)" wait_for imports_running 2
	send a2 hang2; send a3 hang3
	check "client A's third and fourth wait for a slot, parked" wait_for imports_parked 2
	send b-model model --interface 127.0.0.2
	check "client B's model waits too" wait_for imports_parked 3
	send b-plain plain --interface 127.0.0.2
	wait $SENT
	check "B's plain render: 200" [ "$(cat "$T/b-plain.code")" = 200 ]
	check "B's plain render answered before any of A's imports ended (a thread was free)" before b-plain a0
	check "B's model: 200" [ "$(cat "$T/b-model.code")" = 200 ]
	check "B's model imported before A's third and fourth (the client with fewer imports first)" \
		sh -c "[ \$(cat '$T/b-model.done') -lt \$(cat '$T/a2.done') ] && [ \$(cat '$T/b-model.done') -lt \$(cat '$T/a3.done') ]"
	for n in a0 a1 a2 a3; do
		check "A's hanging import $n: 422 at its time limit" [ "$(cat "$T/$n.code")" = 422 ]
	done
	check "no import runs or waits afterwards" sh -c "[ \"\$(curl -s '$URL/metrics' | awk '\$1 == \"umbra_imports_running\" || \$1 == \"umbra_imports_parked\" { s += \$2 } END { print s }')\" = 0 ]"
	stop imp "$PID"
fi

# Overlap (issue 28): one import slot, and an import thread whose import is done gives the slot
# back before it renders. A model in a slow render, then a model whose import hangs: the second
# import runs while the first model renders. Before, the one import thread imported and rendered,
# and the second model waited, parked, until the first was answered.
if start ovl --workers 2 --import-slots 1 --import-timeout-ms 5000; then
	SENT=
	send s-model slow
	check "the slow model renders" wait_for renders_running 1
	send h-model hang0
	check "the next model's import runs, none parked" wait_for importing_none_parked 1/0
	check "... while the first model is still rendering" [ ! -f "$T/s-model.done" ]
	wait $SENT
	check "the slow model: 200" [ "$(cat "$T/s-model.code")" = 200 ]
	check "the hanging import: 422" [ "$(cat "$T/h-model.code")" = 422 ]
	stop ovl "$PID"
fi
finish
