#!/bin/sh
# tests/bench.sh — `make bench`: warm-process medians per stage for the bench scenes, the
# generated 100k / 1M triangle meshes, the cold CLI, and (when present) the HTTP benchmark.
# Env: BUILD, SHARED. Numbers go to stdout; nothing here asserts a time.
set -eu
BUILD=${BUILD:-build}
SHARED=${SHARED:-../shared}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 "$SHARED/bench/gen-mesh-scene.py" 100000 >"$tmp/mesh-100k.json"
python3 "$SHARED/bench/gen-mesh-scene.py" 1000000 >"$tmp/mesh-1m.json"
echo "== warm process (build/tests/bench)"
"$BUILD/tests/bench" -n "${BENCH_RUNS:-15}" "$SHARED/bench/thumb-256.json" "$SHARED/bench/thumb-512.json" \
	"$SHARED/bench/thumb-1024.json" "$SHARED/bench/studio-spots.json" "$SHARED/bench/outdoor-csm.json" "$tmp/mesh-100k.json"
"$BUILD/tests/bench" -n 5 "$tmp/mesh-1m.json"
python3 tests/bench/variants.py "$SHARED/bench" "$tmp/v"
echo
echo "== shadow filters (thumb-512) and directional modes (outdoor-csm)"
"$BUILD/tests/bench" -n "${BENCH_RUNS_SMALL:-7}" "$tmp"/v/thumb512-*.json "$tmp"/v/outdoor-*.json
echo
echo "== outputs: encode cost per format and size (encode column)"
"$BUILD/tests/bench" -n 3 "$tmp"/v/out-*.json
echo
echo "== shadowed lights: studio-spots with 1 / 4 / 16 spot+point lights; warm runs reuse cached maps (maps r/k)"
"$BUILD/tests/bench" -n "${BENCH_RUNS_SMALL:-7}" "$tmp"/v/studio-1lights.json "$tmp"/v/studio-4lights.json "$tmp"/v/studio-16lights.json
echo
echo "== 16-frame turntable (one sheet) against one 256x256 view of the same scene"
"$BUILD/tests/bench" -n 3 "$tmp"/v/studio-single256.json "$tmp"/v/studio-turntable16.json
echo
echo "== imported models (binary STL, inline base64): cold import every run, then cached"
"$BUILD/tests/bench" -n 3 -c "$tmp"/v/model-10k.json "$tmp"/v/model-100k.json "$tmp"/v/model-1m.json
"$BUILD/tests/bench" -n 3 "$tmp"/v/model-10k.json "$tmp"/v/model-100k.json "$tmp"/v/model-1m.json
echo
echo "== model import isolation: the same STL imported cold in-process and in the sandbox (api/sandbox.h)"
"$BUILD/tests/import_bench" -n "${BENCH_RUNS_SMALL:-7}" 1000 100000
echo
echo "== cold CLI (new process each: device + pipelines + first-use JIT), thumb-512: PNG, and EXR with the shadow AOV"
python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); s["output"]={"format":"exr","aovs":["shadow"]}; print(json.dumps(s))' \
	"$SHARED/bench/thumb-512.json" >"$tmp/thumb512-aov.json"
for i in 1 2 3; do
	s=$(date +%s%N)
	"$BUILD/umbra-render" "$SHARED/bench/thumb-512.json" -o "$tmp/cold.png"
	e=$(date +%s%N)
	"$BUILD/umbra-render" "$tmp/thumb512-aov.json" -o "$tmp/cold.exr"
	f=$(date +%s%N)
	echo "run $i: png $(( (e - s) / 1000000 )) ms, exr+aov $(( (f - e) / 1000000 )) ms"
done
if [ -x "$BUILD/tests/http_bench" ] && [ -f tests/bench/http_bench.sh ]; then
	echo
	echo "== HTTP (umbrad over loopback)"
	BUILD=$BUILD SHARED=$SHARED sh tests/bench/http_bench.sh
fi
