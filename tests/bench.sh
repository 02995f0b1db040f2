#!/bin/sh
# tests/bench.sh — `make bench`: the naive floor (../shared/floor, step c) and umbra side by side,
# warm-process medians per stage for the bench scenes, the generated 100k / 1M triangle meshes,
# the cold CLI and the HTTP benchmark, then the ratio table of issue 12 (tests/bench/ratios.py).
# Env: BUILD, SHARED; BENCH_ONLY=ratios runs only what the ratio table needs, with fewer runs
# (`make bench-quick`); BENCH_ONLY=farm only the farm benchmark on new models (`make bench-farm`:
# tests/bench/farm_bench.py on the corpus of tests/bench/farm_corpus.py). BENCH_BEFORE=DIR (the
# build folder of an older checkout) also runs that build's bench and CLI in the same run and
# prints its ratio table first ("before").
# Numbers go to stdout; nothing here asserts a time.
set -eu
BUILD=${BUILD:-build}
SHARED=${SHARED:-../shared}
QUICK=0
[ "${BENCH_ONLY:-}" = ratios ] && QUICK=1
RUNS=${BENCH_RUNS:-15}
[ $QUICK = 1 ] && RUNS=${BENCH_RUNS:-7}
tmp=$(mktemp -d)
log=$tmp/log
mkdir -p "$log"
trap 'rm -rf "$tmp"' EXIT

# The farm on models it has never seen (issue 28): farm CLI, umbrad at 4 clients, f3d. The corpus
# (~140 MB, ~10-15 s to write) is kept in $BUILD/bench-corpus/<hash of farm_corpus.py>/, so a
# changed generator writes a new one and the old one is removed.
farm_models() {
	echo "== farm: new models (tests/bench/farm_bench.py: models never imported before, 10k/100k/1M triangles)"
	key=$(sha256sum tests/bench/farm_corpus.py | cut -c1-12)
	corpus=$BUILD/bench-corpus/$key
	if [ ! -s "$corpus/manifest.json" ]; then
		rm -rf "$BUILD/bench-corpus"
		mkdir -p "$BUILD/bench-corpus"
		python3 tests/bench/farm_corpus.py "$corpus.tmp" 2>"$tmp/corpus.log" ||
			{ cat "$tmp/corpus.log" >&2; exit 1; }
		mv "$corpus.tmp" "$corpus"
	fi
	python3 tests/bench/farm_bench.py "$BUILD" "$corpus"
}
if [ "${BENCH_ONLY:-}" = farm ]; then
	farm_models
	exit 0
fi
python3 tests/bench/variants.py "$SHARED/bench" "$tmp/v"

# Side by side: rounds of the floor, then umbra's thumbnails (and the older build's), so that
# each sees the same load; ratios.py takes medians over the rounds. --retries 0: no waiting for
# quiet, the ratio is what counts.
floor() {
	"$BUILD/floor/limits" --steps c --runs "${FLOOR_RUNS:-11}" --quiet-wait 0 --retries 0 --out "$BUILD/floor/out" |
		grep '^| c' | tee -a "$log/floor.txt"
}
thumbs() { # BUILD_DIR LOG
	"$1/tests/bench" -n "$RUNS" "$SHARED/bench/thumb-256.json" "$SHARED/bench/thumb-512.json" | tee -a "$2"
	# A new model's thumbnail (issue 28): 100k vertex-coloured triangles drawn in full, its sun
	# map drawn every run (-s: as for a model never seen before); the model itself stays imported.
	"$1/tests/bench" -n "$RUNS" -s -a "$tmp/v" "$tmp/v/thumb256-colour-100k.json" "$tmp/v/thumb256-colour-10k.json" |
		tee -a "$2"
}
rest() { # BUILD_DIR LOG: the rows compared with thumb-512
	"$1/tests/bench" -n 5 "$SHARED/bench/thumb-512.json" "$SHARED/bench/studio-spots.json" | tee -a "$2"
	# the 1M model: by path (a cached import: no 70 MB JSON to parse), and inline
	"$1/tests/bench" -n 5 -a "$tmp/v" "$tmp/v/studio-16lights.json" "$tmp/v/model-1m-path.json" \
		"$tmp/v/model-1m.json" | tee -a "$2"
}
echo "== side by side: the floor (step c, MSAA 1 and 4) and umbra warm (build/tests/bench), in rounds"
[ -n "${BENCH_BEFORE:-}" ] && echo "   (each round also runs the older build $BENCH_BEFORE)"
for r in $(seq "${BENCH_ROUNDS:-3}"); do
	floor
	thumbs "$BUILD" "$log/warm.txt"
	[ -n "${BENCH_BEFORE:-}" ] && thumbs "$BENCH_BEFORE" "$log/warm-before.txt"
done
floor
rest "$BUILD" "$log/warm.txt"
[ -n "${BENCH_BEFORE:-}" ] && rest "$BENCH_BEFORE" "$log/warm-before.txt"

if [ $QUICK = 0 ]; then
	python3 "$SHARED/bench/gen-mesh-scene.py" 100000 >"$tmp/mesh-100k.json"
	python3 "$SHARED/bench/gen-mesh-scene.py" 1000000 >"$tmp/mesh-1m.json"
	echo
	echo "== warm process (build/tests/bench)"
	"$BUILD/tests/bench" -n "$RUNS" "$SHARED/bench/thumb-1024.json" "$SHARED/bench/outdoor-csm.json" "$tmp/mesh-100k.json"
	"$BUILD/tests/bench" -n 5 "$tmp/mesh-1m.json"
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
	farm_models
fi
echo
echo "== cold CLI (new process each: device + pipelines + first-use JIT), thumb-512: PNG, and EXR with the shadow AOV"
python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); s["output"]={"format":"exr","aovs":["shadow"]}; print(json.dumps(s))' \
	"$SHARED/bench/thumb-512.json" >"$tmp/thumb512-aov.json"
for i in $( [ $QUICK = 1 ] && echo 1 || echo 1 2 3); do
	s=$(date +%s%N)
	"$BUILD/umbra-render" "$SHARED/bench/thumb-512.json" -o "$tmp/cold.png"
	e=$(date +%s%N)
	"$BUILD/umbra-render" "$tmp/thumb512-aov.json" -o "$tmp/cold.exr"
	f=$(date +%s%N)
	echo "run $i: png $(( (e - s) / 1000000 )) ms, exr+aov $(( (f - e) / 1000000 )) ms"
	if [ -n "${BENCH_BEFORE:-}" ]; then
		s=$(date +%s%N)
		"$BENCH_BEFORE/umbra-render" "$SHARED/bench/thumb-512.json" -o "$tmp/cold.png"
		e=$(date +%s%N)
		"$BENCH_BEFORE/umbra-render" "$tmp/thumb512-aov.json" -o "$tmp/cold.exr"
		f=$(date +%s%N)
		echo "before $i: png $(( (e - s) / 1000000 )) ms, exr+aov $(( (f - e) / 1000000 )) ms" >>"$log/cold-before.txt"
	fi
done | tee "$log/cold.txt"
if [ -x "$BUILD/tests/http_bench" ] && [ -f tests/bench/http_bench.sh ]; then
	echo
	echo "== HTTP (umbrad over loopback), between two in-process runs of the same scene (the ratio's other side)"
	"$BUILD/tests/bench" -n 60 "$SHARED/bench/thumb-256.json" | tee -a "$log/http-inproc.txt"
	# The ratio's HTTP side, between two in-process runs of 60 images (~0.3 s each): thumb-256 at
	# 4 clients, 600 requests (~3 s), against a fresh daemon (its ready RSS is the warm figure).
	# A closed loop's rate also counts the pipeline filling and draining once: with 64 requests
	# that alone cost 3-5 % (0.92-0.97 of the in-process rate, 0.98-1.02 with 600), with 16 (the
	# rows of every scene below) more. 200 warm-up requests first, as the in-process side has its
	# warm-up run: a fresh daemon's first few hundred ran ~3 % slower.
	HTTP_BENCH_CONC=4 HTTP_BENCH_SECONDS=${HTTP_BENCH_SECONDS:-15} HTTP_BENCH_REQUESTS=${HTTP_BENCH_REQUESTS:-600} \
		HTTP_BENCH_WARMUP=${HTTP_BENCH_WARMUP:-200} \
		HTTP_BENCH_SCENES="$SHARED/bench/thumb-256.json" \
		BUILD=$BUILD SHARED=$SHARED sh tests/bench/http_bench.sh | tee "$log/http-ratio.txt"
	[ $QUICK = 1 ] || BUILD=$BUILD SHARED=$SHARED sh tests/bench/http_bench.sh | tee "$log/http.txt"
	"$BUILD/tests/bench" -n 60 "$SHARED/bench/thumb-256.json" | tee -a "$log/http-inproc.txt"
fi
echo
[ -n "${BENCH_BEFORE:-}" ] && python3 tests/bench/ratios.py "$log" before && echo
python3 tests/bench/ratios.py "$log"
