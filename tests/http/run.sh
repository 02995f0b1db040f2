#!/bin/sh
# tests/http/run.sh — black-box tests of $BUILD/umbrad over loopback (127.0.0.1, ephemeral
# ports) with curl; contract §5. Prints "ok - x" / "FAIL - x" per test and, last,
# "N passed, N failed". Env: BUILD (build dir), SHARED (../shared), ASAN=1 or a BUILD path
# containing "asan" for fewer repetitions, UMBRA_VALIDATION (tests/run.sh sets 1: a daemon that
# saw validation messages exits non-zero, which fails its exit test).
. tests/http/lib.sh

# ---- scenes ----

scene() { # scene W H MSAA SEGMENTS EXTRA_ROOT_MEMBERS
	cat <<EOF2
{"width": $1, "height": $2,
 "camera": {"type": "perspective", "position": [4, 3, 4], "target": [0, 0.8, 0], "up": [0, 1, 0], "fov_y": 40},
 "materials": {"grey": {"base_color": [0.7, 0.7, 0.7], "roughness": 0.8, "metallic": 0}},
 "objects": [
  {"shape": "plane", "size": [10, 10], "material": "grey"},
  {"shape": "sphere", "radius": 1, "segments": $4, "material": "grey", "transform": {"translation": [0, 1, 0]}}
 ],
 "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3], "intensity": 3, "shadow": {"filter": "pcf"}}],
 "shadows": {"resolution": 512},
 "output": {"msaa": $3}$5}
EOF2
}
scene 64 64 1 32 "" >"$T/small.json"
scene 64 48 1 32 "" >"$T/small-64x48.json"
# The flood scene must keep one worker busy for a while on lavapipe; the priority check's
# occupier must outlast the queueing of the two requests behind it (0.3 s and two curls'
# start-up) by a margin: five soft suns over 2048^2, ~1 s warm (one hard-edged sun took
# ~0.3 s since spheres are drawn as proxies, too close).
scene 512 512 4 256 ', "x-flood": 1' | sed 's/"resolution": 512/"resolution": 2048/' >"$T/slow.json"
scene 2048 2048 4 256 ', "x-flood": 2' | sed 's/"resolution": 512/"resolution": 2048/' |
	sed 's/"shadow": {"filter": "pcf"}/"angular_diameter": 3, "shadow": {"filter": "pcss"}/' |
	sed 's/"lights": \[\(.*\)\],$/"lights": [\1, \1, \1, \1, \1],/' >"$T/slower.json"
scene 2000 2000 1 32 "" >"$T/pixels.json"
scene 64 64 1 2048 "" >"$T/triangles.json"
sed 's/"resolution": 512/"resolution": 4096/' "$T/small.json" >"$T/shadowres.json"
sed 's/"lights": \[\(.*\)\],$/"lights": [\1, \1, \1, \1, \1],/' "$T/small.json" >"$T/lights.json"
printf '{"width": 64, "height": 64, "camera": {' >"$T/malformed.json"
sed 's/"intensity": 3,/"intensity": 3, "colour": [1, 1, 1],/' "$T/small.json" >"$T/unknown.json"
sed 's/"width": 64/"width": "64"/' "$T/small.json" >"$T/wrongtype.json"
sed 's/"width": 64/"width": 0/' "$T/small.json" >"$T/range.json"
sed 's/"msaa": 1/"msaa": 1, "format": "exr"/' "$T/small.json" >"$T/exr.json"
for o in 'webp:"format": "webp"' 'webp-q80:"format": "webp", "quality": 80' 'webp-q101:"format": "webp", "quality": 101' \
	'q80:"quality": 80' 'webp-alpha:"format": "webp", "transparent": true' 'png-alpha:"transparent": true' \
	'avif:"format": "avif"' 'avif-q70:"format": "avif", "quality": 70' 'avif-alpha:"format": "avif", "transparent": true'; do
	sed "s/\"msaa\": 1/\"msaa\": 1, ${o#*:}/" "$T/small.json" >"$T/${o%%:*}.json"
done
mkdir -p "$T/assets"
printf 'v -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n' >"$T/assets/tri.obj"
sed 's/"objects": \[/"objects": [{"shape": "model", "path": "tri.obj"},/' "$T/small.json" >"$T/model-path.json"
sed 's/"objects": \[/"objects": [{"shape": "model", "path": "..\/small.json"},/' "$T/small.json" >"$T/model-escape.json"
sed 's/"objects": \[/"objects": [{"shape": "model", "part": "mesh", "format": "obj"},/' "$T/small.json" >"$T/model-part.json"
head -c 2097152 /dev/zero | tr '\0' ' ' >"$T/huge.json"

# ==== flags ====
"$UMBRAD" --help >"$T/help.out" 2>&1; rc=$?
check "--help exits 0 and lists the flags" sh -c "[ $rc = 0 ] && grep -q -- '--max-body' '$T/help.out' && grep -q -- '--deadline-ms' '$T/help.out'"
"$UMBRAD" --no-such-flag >/dev/null 2>&1; rc=$?
check "unknown flag exits 2" [ $rc = 2 ]
UMBRA_WORKERS=zero "$UMBRAD" >/dev/null 2>&1; rc=$?
check "bad UMBRA_WORKERS exits 2" [ $rc = 2 ]
"$UMBRAD" --warm-up sometimes >"$T/warm.out" 2>&1; rc=$?
check "--warm-up other than defaults|all exits 2, naming the flag" sh -c "[ $rc = 2 ] && grep -q -- '--warm-up' '$T/warm.out'"

# ==== main daemon ====
echo "# starting the main daemon (reps $REPS)"
start main --asset-root "$T/assets" --pipeline-cache "$T/pipeline.cache" --max-body 1M --max-pixels 1000000 --max-triangles 200000 --max-lights 4 \
	--max-shadow-resolution 2048 --queue 64 || { echo "$pass passed, $fail failed"; exit 1; }
MAIN=$PID
MAIN_URL=$URL
if [ "$FIRST_READY" = 503 ]; then
	check "readyz 503 with Retry-After before ready" grep -qi '^Retry-After:' "$T/main.first-ready.hdr"
fi
grep -q "listening on http://127.0.0.1:$(cat "$T/main.port")" "$T/main.log" && ok "start-up log names the bound port" || nok "start-up log names the bound port"
check "--warm-up defaults: the MSAA 4 variants and the thumbnail preset are warmed, MSAA 1 ones left to first use" \
	sh -c "grep -q \"warm-up 'msaa 4, directional pcf'\" '$T/main.log' && grep -q \"warm-up 'thumbnail preset\" '$T/main.log' && ! grep -q \"warm-up 'msaa 1\" '$T/main.log'"

# -- GET routes
c=$(get h /healthz); check "GET /healthz 200" [ "$c" = 200 ]
c=$(get h /healthz -I); check "HEAD /healthz 200" [ "$c" = 200 ]
c=$(get r /readyz); check "GET /readyz 200 when ready" [ "$c" = 200 ]
c=$(get i /v1/info)
check "GET /v1/info 200 JSON" [ "$c" = 200 ]
check "/v1/info has version, device, driver, limits, filters, formats" python3 - "$T/i.body" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
ok = all(k in d for k in ("version", "device", "driver", "limits", "filters", "formats"))
ok = ok and set(["hard", "pcf", "pcss", "vsm", "evsm"]) <= set(d["filters"]) and {"png", "exr", "webp", "avif"} <= set(d["formats"])
ok = ok and d["limits"].get("max_pixels") == 1000000
print("# info:", json.dumps(d)[:300])
sys.exit(0 if ok else 1)
PY
c=$(get m /metrics)
check "GET /metrics 200 text/plain" [ "$c" = 200 ]
case "$(hdr m Content-Type)" in text/plain*) ok "/metrics Content-Type text/plain" ;; *) nok "/metrics Content-Type text/plain" "$(hdr m Content-Type)" ;; esac

# -- errors of the routing layer
c=$(get e404 /nope); check "unknown route 404" [ "$c" = 404 ]
check "404 is problem+json" problem e404 404 -
c=$(get e405 /v1/render); check "GET /v1/render 405" [ "$c" = 405 ]
check "405 has Allow: POST" [ "$(hdr e405 Allow)" = POST ]
check "405 is problem+json" problem e405 405 -
c=$(curl -s -o /dev/null -D "$T/e405b.hdr" -w '%{http_code}' -X POST --data x "$URL/healthz")
check "POST /healthz 405 with Allow GET" sh -c "[ $c = 405 ] && tr -d '\r' <'$T/e405b.hdr' | grep -qi '^Allow:.*GET'"
c=$(curl -s --max-time 30 -o "$T/e415.body" -D "$T/e415.hdr" -w '%{http_code}' -H 'Content-Type: text/plain' \
	--data-binary "@$T/small.json" "$URL/v1/render")
check "text/plain body 415" [ "$c" = 415 ]
check "415 is problem+json" problem e415 415 -
c=$(curl -s -o /dev/null -w '%{http_code}' --max-time 30 --data-binary "@$T/small.json" -H 'Content-Type:' "$URL/v1/render")
check "missing Content-Type 415" [ "$c" = 415 ]
c=$(post e413 "$T/huge.json"); check "2 MiB body over --max-body 1M: 413" [ "$c" = 413 ]
check "413 is problem+json" problem e413 413 -
check "413 says how a large model fits: a multipart part, or path under the asset root" python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))["detail"]
sys.exit(0 if "--max-body" in d and "multipart/form-data part" in d and "\"path\"" in d else 1)' "$T/e413.body"
c=$(post e413c "$T/huge.json" -H 'Transfer-Encoding: chunked'); check "chunked body over --max-body: 413" [ "$c" = 413 ]

# -- scene errors (400 with the member's pointer; 422 over the limits)
c=$(post malformed "$T/malformed.json"); check "malformed JSON 400" [ "$c" = 400 ]
check "malformed JSON problem+json" problem malformed 400 -
c=$(post unknown "$T/unknown.json"); check "unknown member 400" [ "$c" = 400 ]
check "unknown member pointer /lights/0/colour" problem unknown 400 /lights/0/colour
c=$(post wrongtype "$T/wrongtype.json"); check "wrong type 400" [ "$c" = 400 ]
check "wrong type pointer /width" problem wrongtype 400 /width
c=$(post range "$T/range.json"); check "out-of-range value 400" [ "$c" = 400 ]
check "out-of-range pointer /width" problem range 400 /width
c=$(post pixels "$T/pixels.json"); check "over --max-pixels 422" [ "$c" = 422 ]
check "422 is problem+json" problem pixels 422 -
c=$(post tris "$T/triangles.json"); check "over --max-triangles 422" [ "$c" = 422 ]
c=$(post lights "$T/lights.json"); check "over --max-lights 422" [ "$c" = 422 ]
c=$(post shres "$T/shadowres.json"); check "over --max-shadow-resolution 422" [ "$c" = 422 ]
c=$(post prio "$T/small.json" -H 'X-Priority: urgent'); check "unknown X-Priority 400" [ "$c" = 400 ]

# -- renders
c=$(post r1 "$T/small.json"); check "POST /v1/render 200" [ "$c" = 200 ]
check "Content-Type image/png" [ "$(hdr r1 Content-Type)" = image/png ]
check "valid PNG 64x64" [ "$(png_size "$T/r1.body")" = 64x64 ]
st=$(hdr r1 Server-Timing)
echo "# Server-Timing: $st"
check "Server-Timing has parse, upload, shadow, main, readback, encode" sh -c '
	for s in parse upload shadow main readback encode; do
		echo "$1" | grep -Eq "(^|[ ,])$s;dur=[0-9.]+" || exit 1
	done' - "$st"
etag=$(hdr r1 ETag)
check "strong ETag" sh -c "echo '$etag' | grep -Eq '^\"[^\"]+\"\$'"
check "generated X-Request-Id" [ -n "$(hdr r1 X-Request-Id)" ]
c=$(post r2 "$T/small.json" -H 'X-Request-Id: test-id-42')
check "caller's X-Request-Id echoed" [ "$(hdr r2 X-Request-Id)" = test-id-42 ]
check "same body, same bytes" cmp -s "$T/r1.body" "$T/r2.body"
check "same body, same ETag" [ "$(hdr r2 ETag)" = "$etag" ]
c=$(post r3 "$T/small-64x48.json"); check "other body 200, 64x48" [ "$(png_size "$T/r3.body")" = 64x48 ]
check "other body, other ETag" [ "$(hdr r3 ETag)" != "$etag" ]
# RFC 9110 §13.1.2: a POST whose If-None-Match lists its ETag is a 412 (304 is for GET and HEAD).
c=$(post r412 "$T/small.json" -H "If-None-Match: $etag"); check "If-None-Match with the ETag on a POST: 412 problem+json" eval '[ "$c" = 412 ] && problem r412 412 ""'
check "the 412 carries the ETag" [ "$(hdr r412 ETag)" = "$etag" ]
# The ETag is the parsed scene's: the same scene spelled otherwise (members reordered, other
# whitespace, 1.0 for 1) has the same one.
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(json.dumps(dict(reversed(list(d.items()))), indent=3))' "$T/small.json" >"$T/small-reordered.json"
c=$(post rre "$T/small-reordered.json"); check "re-serialized scene: 200, the same ETag" eval '[ "$c" = 200 ] && [ "$(hdr rre ETag)" = "$etag" ]'
check "POST answers say Cache-Control: no-cache" [ "$(hdr r1 Cache-Control)" = no-cache ]
c=$(post rexr "$T/small.json" -H 'Accept: image/x-exr'); check "Accept: image/x-exr 200" [ "$c" = 200 ]
check "Accept: image/x-exr gives image/x-exr" [ "$(hdr rexr Content-Type)" = image/x-exr ]
check "EXR magic" is_exr "$T/rexr.body"
check "Accept changes the ETag" [ "$(hdr rexr ETag)" != "$etag" ]
c=$(post rexr2 "$T/exr.json"); check "output.format exr: image/x-exr" sh -c "[ $c = 200 ] && [ '$(hdr rexr2 Content-Type)' = image/x-exr ]"
c=$(post rpng "$T/small.json" -H 'Accept: image/png, image/x-exr;q=0.5'); check "Accept preferring PNG: image/png" [ "$(hdr rpng Content-Type)" = image/png ]
c=$(post rjpg "$T/small.json" -H 'Accept: image/jpeg'); check "Accept: image/jpeg (neither format): 406 problem+json" eval '[ "$c" = 406 ] && problem rjpg 406 ""'
c=$(post rjpg2 "$T/small.json" -H 'Accept: image/jpeg, */*;q=0.1'); check "Accept: image/jpeg, */*;q=0.1: 200 PNG" eval '[ "$c" = 200 ] && [ "$(hdr rjpg2 Content-Type)" = image/png ]'
# -- WebP: output.format, Accept, quality; decoded by the system's libwebp (tests/util/webp.py)
webp() { python3 tests/util/webp.py "$@"; }
c=$(post rwebp "$T/webp.json"); check "output.format webp: 200 image/webp" sh -c "[ $c = 200 ] && [ '$(hdr rwebp Content-Type)' = image/webp ]"
check "WebP: RIFF/WEBP magic, lossless, 64x64, opaque" [ "$(webp info "$T/rwebp.body")" = "64 64 lossless opaque" ]
check "lossless WebP decodes to the PNG's pixels exactly" [ "$(webp compare "$T/rwebp.body" "$T/r1.body")" = "inf 0" ]
c=$(post rwebp2 "$T/small.json" -H 'Accept: image/webp'); check "Accept: image/webp gives image/webp" sh -c "[ $c = 200 ] && [ '$(hdr rwebp2 Content-Type)' = image/webp ]"
check "Accept: image/webp: the same bytes as output.format webp" cmp -s "$T/rwebp.body" "$T/rwebp2.body"
check "Accept: image/webp: its own ETag" sh -c "[ '$(hdr rwebp2 ETag)' != '$etag' ] && [ '$(hdr rwebp2 ETag)' != '$(hdr rexr ETag)' ]"
c=$(post rwebp3 "$T/small.json" -H 'Accept: image/webp;q=0.5, image/png'); check "Accept preferring PNG over WebP: image/png" [ "$(hdr rwebp3 Content-Type)" = image/png ]
c=$(post rwebp4 "$T/small.json" -H 'Accept: image/avif, image/webp, */*;q=0.8'); check "a browser's image Accept: image/webp" [ "$(hdr rwebp4 Content-Type)" = image/webp ]
c=$(post rwebp5 "$T/exr.json" -H 'Accept: image/webp'); check "output.format exr wins over Accept: image/webp" [ "$(hdr rwebp5 Content-Type)" = image/x-exr ]
c=$(post rq80 "$T/webp-q80.json"); cmp80=$(webp compare "$T/rq80.body" "$T/r1.body")
check "quality 80: lossy WebP, PSNR ${cmp80% *} dB against the PNG (> 30), alpha exact" \
	sh -c "[ $c = 200 ] && [ '$(webp info "$T/rq80.body")' = '64 64 lossy opaque' ] && [ '${cmp80#* }' = 0 ] && \
	python3 -c 'import sys; sys.exit(not float(\"${cmp80% *}\") > 30)'"
check "quality 80: smaller than lossless" [ "$(wc -c <"$T/rq80.body")" -lt "$(wc -c <"$T/rwebp.body")" ]
c=$(post rq101 "$T/webp-q101.json"); check "quality 101: 400 at /output/quality" eval '[ "$c" = 400 ] && problem rq101 400 /output/quality'
c=$(post rq80p "$T/q80.json"); check "quality without format, answer PNG: 400 at /output/quality" eval '[ "$c" = 400 ] && problem rq80p 400 /output/quality'
c=$(post rq80w "$T/q80.json" -H 'Accept: image/webp'); check "quality without format, Accept: image/webp: lossy WebP" \
	sh -c "[ $c = 200 ] && [ '$(webp info "$T/rq80w.body")' = '64 64 lossy opaque' ]"
c=$(post ralpha "$T/webp-alpha.json"); c2=$(post palpha "$T/png-alpha.json")
check "transparent WebP keeps alpha, pixels equal to the transparent PNG's" \
	sh -c "[ $c = 200 ] && [ $c2 = 200 ] && [ '$(webp info "$T/ralpha.body")' = '64 64 lossless alpha' ] && [ '$(webp compare "$T/ralpha.body" "$T/palpha.body")' = 'inf 0' ]"
# -- AVIF: the same members; decoded by libavif's avifdec (tests/util/avif.py)
avif() { python3 tests/util/avif.py "$@"; }
c=$(post ravif "$T/avif.json"); check "output.format avif: 200 image/avif" sh -c "[ $c = 200 ] && [ '$(hdr ravif Content-Type)' = image/avif ]"
check "AVIF: lossless, 64x64, opaque" [ "$(avif info "$T/ravif.body")" = "64 64 lossless opaque" ]
check "lossless AVIF decodes to the PNG's pixels exactly" [ "$(avif compare "$T/ravif.body" "$T/r1.body")" = "inf 0" ]
c=$(post ravif2 "$T/small.json" -H 'Accept: image/avif'); check "Accept: image/avif: the same bytes as output.format avif, its own ETag" \
	sh -c "[ $c = 200 ] && cmp -s '$T/ravif.body' '$T/ravif2.body' && [ '$(hdr ravif2 ETag)' != '$etag' ] && [ '$(hdr ravif2 ETag)' != '$(hdr rwebp2 ETag)' ]"
c=$(post ravif3 "$T/avif-q70.json"); cmp70=$(avif compare "$T/ravif3.body" "$T/r1.body")
check "quality 70: lossy AVIF, PSNR ${cmp70% *} dB against the PNG (> 30), smaller than lossless" \
	sh -c "[ $c = 200 ] && [ '$(avif info "$T/ravif3.body")' = '64 64 lossy opaque' ] && [ '${cmp70#* }' = 0 ] && \
	       python3 -c 'import sys; sys.exit(not float(sys.argv[1]) > 30)' '${cmp70% *}' && [ $(wc -c <"$T/ravif3.body") -lt $(wc -c <"$T/ravif.body") ]"
c=$(post ravif4 "$T/avif-q70.json"); check "AVIF: the same scene gives the same bytes" cmp -s "$T/ravif3.body" "$T/ravif4.body"
c=$(post ravif5 "$T/avif-alpha.json")
check "transparent AVIF keeps alpha, pixels equal to the transparent PNG's" \
	sh -c "[ $c = 200 ] && [ '$(avif info "$T/ravif5.body")' = '64 64 lossless alpha' ] && [ '$(avif compare "$T/ravif5.body" "$T/palpha.body")' = 'inf 0' ]"
c=$(post bulk "$T/small.json" -H 'X-Priority: bulk'); check "X-Priority: bulk 200" [ "$c" = 200 ]
c=$(post mpath "$T/model-path.json"); check "model by path under --asset-root 200" [ "$c" = 200 ]
# The answer depends on the file under --asset-root: when it changes, so must the ETag, and the
# old ETag must not earn a 412.
mtag=$(hdr mpath ETag)
c=$(post mpath412 "$T/model-path.json" -H "If-None-Match: $mtag"); check "asset model, same file: 412" [ "$c" = 412 ]
cp "$T/assets/tri.obj" "$T/tri.obj.orig"
printf 'v -1 0 -1\nv 1 0 -1\nv 0 0.5 0\nf 1 2 3\n' >"$T/assets/tri.obj"
c=$(post mpath2 "$T/model-path.json" -H "If-None-Match: $mtag"); check "asset model file changed: 200, not 412" [ "$c" = 200 ]
check "asset model file changed: other ETag" [ "$(hdr mpath2 ETag)" != "$mtag" ]
cp "$T/tri.obj.orig" "$T/assets/tri.obj"
c=$(post mesc "$T/model-escape.json"); check "model path escaping --asset-root 400" [ "$c" = 400 ]
check "escaping path problem names the member" problem mesc 400 /objects/0/path
c=$(curl -s --max-time 60 -o "$T/mp.body" -D "$T/mp.hdr" -w '%{http_code}' -F "scene=@$T/model-part.json;type=application/json" \
	-F "mesh=@$T/assets/tri.obj;type=application/octet-stream" "$URL/v1/render")
check "multipart/form-data scene + model part 200" sh -c "[ $c = 200 ] && [ '$(png_size "$T/mp.body")' = 64x64 ]"
c=$(curl -s --max-time 60 -o "$T/mp2.body" -D "$T/mp2.hdr" -w '%{http_code}' -F "mesh=@$T/assets/tri.obj" "$URL/v1/render")
check "multipart without a scene part 400" [ "$c" = 400 ]

# -- a model material feature the renderer does not do is named in Umbra-Warnings (never silent)
python3 - "$T/small.json" "$T/model-warn.json" <<'PY'
import base64, json, struct, sys
pos = struct.pack('<9f', -1, 0, 0, 1, 0, 0, 0, 1, 0)
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
     "extensionsUsed": ["KHR_materials_iridescence"],
     "materials": [{"extensions": {"KHR_materials_iridescence": {"iridescenceFactor": 1}}}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
     "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64," + base64.b64encode(pos).decode()}],
     "bufferViews": [{"buffer": 0, "byteLength": 36}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, 0, 0], "max": [1, 1, 0]}]}
doc = json.load(open(sys.argv[1]))
doc["objects"].append({"shape": "model", "format": "gltf", "data": base64.b64encode(json.dumps(g).encode()).decode()})
json.dump(doc, open(sys.argv[2], "w"))
PY
c=$(post mwarn "$T/model-warn.json")
w=$(hdr mwarn Umbra-Warnings)
case "$w" in /objects/*KHR_materials_iridescence*) wok=1 ;; *) wok=0 ;; esac
check "model with an unsupported material extension: 200" [ "$c" = 200 ]
check "Umbra-Warnings names the extension under its object's pointer ($w)" [ "$wok" = 1 ]
check "a model without such data: no Umbra-Warnings" [ -z "$(hdr mp Umbra-Warnings)" ]

# -- 20 concurrent requests
cpids=""
i=0
while [ $i -lt 20 ]; do
	curl -s --max-time 120 -o "$T/c$i.png" -w '%{http_code}' -H 'Content-Type: application/json' \
		--data-binary "@$T/small.json" "$URL/v1/render" >"$T/c$i.code" &
	cpids="$cpids $!"
	i=$((i + 1))
done
wait $cpids
bad=0
i=0
while [ $i -lt 20 ]; do
	[ "$(cat "$T/c$i.code")" = 200 ] && cmp -s "$T/c$i.png" "$T/r1.body" || bad=$((bad + 1))
	i=$((i + 1))
done
check "20 concurrent renders all 200 and byte-identical" [ $bad -eq 0 ]

c=$(get metrics /metrics)
check "metrics count the 200 renders" [ "$(metric 'umbra_requests_total{route="/v1/render",status="200"}')" -ge 25 ]
check "metrics have the stage histograms" grep -q 'umbra_stage_seconds_bucket{stage="shadow",le="+Inf"}' "$T/metrics.body"
check "metrics have the request-duration histogram" grep -q '^umbra_request_duration_seconds_count{route="/v1/render"}' "$T/metrics.body"
check "metrics have queue depth and in-flight gauges" sh -c "grep -q '^umbra_queue_depth ' '$T/metrics.body' && grep -q '^umbra_renders_in_flight ' '$T/metrics.body'"
check "metrics have shadow-map reuse" grep -q '^umbra_shadow_maps_reused_total ' "$T/metrics.body"
check "metrics have atlas occupancy" grep -q '^umbra_atlas_occupancy_ratio ' "$T/metrics.body"
check "metrics count 413/415/422" sh -c "grep -q 'status=\"413\"' '$T/metrics.body' && grep -q 'status=\"415\"' '$T/metrics.body' && grep -q 'status=\"422\"' '$T/metrics.body'"
check "access log line per request, with the client's address" grep -q 'info  POST /v1/render 200 .*id=test-id-42 client=127.0.0.1' "$T/main.log"

# -- resources over $REPS sequential small renders (keep-alive batches of 25); the growth is
# measured after the first fifth, once caches and allocator pools have settled.
fd0=$(fd_count $MAIN); rss0=$(rss_kb $MAIN)
n=0; bad=0; fd1=""
while [ $n -lt "$REPS" ]; do
	set --
	k=0
	while [ $k -lt 25 ]; do set -- "$@" -o /dev/null "$URL/v1/render"; k=$((k + 1)); done
	codes=$(curl -s --max-time 300 -w '%{http_code}\n' -H 'Content-Type: application/json' \
		--data-binary "@$T/small.json" "$@")
	bad=$((bad + $(echo "$codes" | grep -vc '^200$')))
	n=$((n + 25))
	if [ -z "$fd1" ] && [ $n -ge $((REPS / 5)) ]; then fd1=$(fd_count $MAIN); rss1=$(rss_kb $MAIN); n1=$n; fi
done
fd2=$(fd_count $MAIN); rss2=$(rss_kb $MAIN)
echo "# $REPS sequential renders: fds $fd0 -> $fd1 (after $n1) -> $fd2; RSS KiB $rss0 -> $rss1 (after $n1) -> $rss2"
check "$REPS sequential renders all 200" [ $bad -eq 0 ]
check "no fd growth over $REPS requests" [ "$fd2" -le $((fd0 + 2)) ]
check "RSS bounded over $REPS requests (< $((RSS_BOUND_KB / 1024)) MiB growth after the first $n1)" [ $((rss2 - rss1)) -lt $RSS_BOUND_KB ]

# ==== flood: one worker, queue of 2 ====
echo "# starting the flood daemon"
# The queue bound comes from the environment here, to cover UMBRA_* variables.
UMBRA_QUEUE=2
export UMBRA_QUEUE
start flood --workers 1
ok_flood=$?
unset UMBRA_QUEUE
if [ $ok_flood -eq 0 ]; then
	FLOOD=$PID
	# Priority: occupy the worker, queue bulk then interactive: the interactive one ends first.
	# Only meaningful when the occupying render outlasts the queueing (it does on lavapipe).
	rm -f "$T/order"
	(curl -s --max-time 120 -o /dev/null -H 'Content-Type: application/json' --data-binary "@$T/slower.json" \
		"$URL/v1/render"; echo "occupier $(date +%s%N)" >>"$T/order") &
	cpids="$!"
	sleep 0.15
	(curl -s --max-time 120 -o /dev/null -H 'Content-Type: application/json' -H 'X-Priority: bulk' \
		--data-binary "@$T/slow.json" "$URL/v1/render"; echo "bulk $(date +%s%N)" >>"$T/order") &
	cpids="$cpids $!"
	sleep 0.15
	t_int=$(date +%s%N)
	(curl -s --max-time 120 -o /dev/null -H 'Content-Type: application/json' -H 'X-Priority: interactive' \
		--data-binary "@$T/small.json" "$URL/v1/render"; echo "interactive $(date +%s%N)" >>"$T/order") &
	cpids="$cpids $!"
	wait $cpids
	t_occ=$(awk '$1 == "occupier" { print $2 }' "$T/order")
	if [ "$t_occ" -lt "$t_int" ]; then
		ok "interactive served before queued bulk # SKIP renders too fast to queue behind"
	else
		check "interactive served before queued bulk" [ "$(grep -v occupier "$T/order" | head -n 1 | cut -d' ' -f1)" = interactive ]
	fi

	# Flood: 16 at once -> 1 rendering + 2 queued; the rest 503 at once with Retry-After.
	cpids=""
	i=0
	while [ $i -lt 16 ]; do
		curl -s --max-time 120 -o "$T/f$i.body" -D "$T/f$i.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
			--data-binary "@$T/slow.json" "$URL/v1/render" >"$T/f$i.code" &
		cpids="$cpids $!"
		i=$((i + 1))
	done
	wait $cpids
	n200=0; n503=0; other=0; noretry=0
	i=0
	while [ $i -lt 16 ]; do
		case "$(cat "$T/f$i.code")" in
		200) n200=$((n200 + 1)) ;;
		503) n503=$((n503 + 1)); f503=f$i; hdr f$i Retry-After | grep -q '^[0-9]' || noretry=$((noretry + 1)) ;;
		*) other=$((other + 1)) ;;
		esac
		i=$((i + 1))
	done
	echo "# flood of 16: $n200 x 200, $n503 x 503, $other other"
	check "flood: every request answered 200 or 503, none hung" [ $other -eq 0 ]
	check "flood: queue full answered 503" [ $n503 -ge 1 ]
	check "flood: 503 carries Retry-After" [ $noretry -eq 0 ]
	# 1 rendering + 2 queued, or 2 when the 16 arrive before the worker took the first one off
	# the queue (a loaded machine): either way every accepted request rendered.
	check "flood: the accepted ones rendered" [ $n200 -ge 2 ]
	[ -n "${f503:-}" ] && check "flood: 503 is problem+json" problem $f503 503 -
	c=$(get metrics /metrics)
	check "metrics count queue rejections" [ "$(metric umbra_queue_rejected_total)" -ge 1 ]
	stop flood $FLOOD
fi

# ==== deadline: --deadline-ms 1 ====
echo "# starting the deadline daemon"
if start deadline --workers 1 --deadline-ms 1 --log-format json; then
	c=$(post d1 "$T/small.json" -H 'X-Request-Id: deadline-1'); check "render past --deadline-ms: 504" [ "$c" = 504 ]
	check "504 is problem+json" problem d1 504 -
	check "--log-format json: every line is a JSON object; the access line has the fields, the client, the problem's detail, and a 5xx at level warn" python3 - "$T/deadline.log" <<'PY'
import json, sys
ok = False
for line in open(sys.argv[1]):
    d = json.loads(line)
    if d.get("request_id") == "deadline-1":
        ok = d["status"] == 504 and d["method"] == "POST" and d["route"] == "/v1/render" and "ms" in d and "bytes" in d \
             and "deadline" in d.get("detail", "") and d.get("pointer") == "" and d.get("level") == "warn" \
             and d.get("client") == "127.0.0.1"
sys.exit(0 if ok else 1)
PY
	stop deadline $PID
fi

# A configuration error with UMBRA_LOG_FORMAT=json is a JSON log line too, and exit 2.
UMBRA_LOG_FORMAT=json "$UMBRAD" --atlas-size 3 2>"$T/badflag.log"; rc=$?
check "UMBRA_LOG_FORMAT=json: a bad flag is exit 2 and one JSON error line" python3 - "$T/badflag.log" "$rc" <<'PY'
import json, sys
lines = open(sys.argv[1]).read().splitlines()
d = json.loads(lines[0]) if len(lines) == 1 else {}
sys.exit(0 if sys.argv[2] == "2" and d.get("level") == "error" and "--atlas-size" in d.get("msg", "") else 1)
PY
"$UMBRAD" --atlas-size 3 2>"$T/badflag.txt"
check "text log format: the bad flag says 'umbrad: --atlas-size ...'" grep -q '^umbrad: --atlas-size: 3 is not a power of two' "$T/badflag.txt"

# ==== SIGTERM under load (main daemon) ====
URL=$MAIN_URL
# Renders taken off the queue: umbra_queue_wait_seconds_count of both priorities.
taken() { awk '/^umbra_queue_wait_seconds_count\{/ { s += $2 } END { print s + 0 }' "$T/metrics.body"; }
get metrics /metrics >/dev/null
base=$(taken)
cpids=""
i=0
while [ $i -lt 8 ]; do
	curl -s --max-time 120 -o "$T/t$i.png" -w '%{http_code}' -H 'Content-Type: application/json' \
		--data-binary "@$T/slow.json" "$URL/v1/render" >"$T/t$i.code" &
	cpids="$cpids $!"
	i=$((i + 1))
done
# Wait until all 8 are accepted (queued or taken by a worker), then SIGTERM.
i=0
while [ $i -lt 300 ]; do
	get metrics /metrics >/dev/null
	taken=$(taken); queued=$(metric umbra_queue_depth)
	[ $((${taken%.*} - ${base%.*} + ${queued%.*})) -ge 8 ] && break
	sleep 0.1; i=$((i + 1))
done
kill -TERM $MAIN
sleep 0.2
c=$(curl -s -o /dev/null -w '%{http_code}' --max-time 5 "$URL/readyz")
check "after SIGTERM no new connection is ready" [ "$c" != 200 ]
wait $MAIN
rc=$?
wait $cpids
bad=0
i=0
while [ $i -lt 8 ]; do
	[ "$(cat "$T/t$i.code")" = 200 ] && [ "$(png_size "$T/t$i.png")" = 512x512 ] || bad=$((bad + 1))
	i=$((i + 1))
done
check "SIGTERM under load: all 8 accepted renders answered 200" [ $bad -eq 0 ]
if [ $rc -eq 0 ]; then ok "main exits 0 after SIGTERM under load"; else
	nok "main exits 0 after SIGTERM under load" "exit $rc"; grep -v ' info ' "$T/main.log" | tail -n 20 | sed 's/^/# /'
fi
check "drain logged" grep -q 'SIGTERM: draining' "$T/main.log"
check "pipeline cache saved at exit" [ -s "$T/pipeline.cache" ]

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
