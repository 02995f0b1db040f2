#!/bin/sh
# tests/cli/run.sh — umbra-render as a user runs it: the thumbnail farm (thumb MODEL...), several
# scenes and a manifest in one process, the JSON-lines report, exit codes, Ctrl-C, and the
# self-placing ground's shadow seen in the image. Models are written here (OBJ, ASCII STL and
# PLY). Prints "ok - x" / "FAIL - x" and, last, "N passed, N failed".
# Env: BUILD (build dir); UMBRA_VALIDATION (tests/run.sh sets 1: any message fails a run).
BUILD=${BUILD:-build}
CLI=$BUILD/umbra-render
PNG="python3 tests/cli/png.py"
T=$(mktemp -d "${TMPDIR:-/tmp}/umbra-cli.XXXXXX")
pass=0
fail=0
ok() { echo "ok - $1"; pass=$((pass + 1)); }
nok() { echo "FAIL - $1${2:+: $2}"; fail=$((fail + 1)); }
check() { n=$1; shift; if "$@"; then ok "$n"; else nok "$n"; fi; }
trap 'rm -rf "$T"' EXIT
# ASan builds: preload the driver after the ASan runtime (see tests/run.sh).
PRELOAD=""
asan_rt=$(ldd "$CLI" 2>/dev/null | awk '/libasan/ { print $3; exit }')
if [ -n "$asan_rt" ]; then
	for lvp in /usr/lib/*/libvulkan_lvp.so /usr/lib64/libvulkan_lvp.so; do
		[ -f "$lvp" ] && PRELOAD="$asan_rt $lvp" && break
	done
fi
cli() { LD_PRELOAD="$PRELOAD" "$CLI" "$@"; }
if [ ! -x "$CLI" ]; then nok "umbra-render built"; echo "$pass passed, $fail failed"; exit 1; fi

# ---- models ----
mkdir -p "$T/models"
cat >"$T/models/cube.obj" <<'EOF2'
v -1 0 -1
v 1 0 -1
v 1 2 -1
v -1 2 -1
v -1 0 1
v 1 0 1
v 1 2 1
v -1 2 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 4 8 7 3
f 1 5 8 4
f 2 3 7 6
EOF2
cat >"$T/models/tetra.stl" <<'EOF2'
solid tetra
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0 1 0
  vertex 1 0 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 0 1
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0 1
  vertex 0 1 0
 endloop
endfacet
facet normal 0.577 0.577 0.577
 outer loop
  vertex 1 0 0
  vertex 0 1 0
  vertex 0 0 1
 endloop
endfacet
endsolid tetra
EOF2
cat >"$T/models/pyramid.ply" <<'EOF2'
ply
format ascii 1.0
element vertex 5
property float x
property float y
property float z
element face 6
property list uchar int vertex_indices
end_header
-1 0 -1
1 0 -1
1 0 1
-1 0 1
0 1.5 0
3 0 1 2
3 0 2 3
3 0 4 1
3 1 4 2
3 2 4 3
3 3 4 0
EOF2
printf 'this is not an STL file\n' >"$T/models/broken.stl"

# ---- thumb: three models and a broken one ----
cli thumb "$T/models/cube.obj" "$T/models/tetra.stl" "$T/models/pyramid.ply" "$T/models/broken.stl" \
	-o "$T/thumbs/" --size 96 -j 2 --no-progress 2>"$T/thumb.err"
rc=$?
check "thumb: one broken model -> exit 2 (invalid input)" [ $rc = 2 ]
for m in cube tetra pyramid; do
	check "thumb: $m.png is a 96x96 PNG" [ "$($PNG size "$T/thumbs/$m.png" 2>/dev/null)" = "96 96" ]
	check "thumb: $m.png has content (>8 colours)" [ "$($PNG distinct "$T/thumbs/$m.png" 2>/dev/null || echo 0)" -gt 8 ]
done
check "thumb: nothing written for the broken model" [ ! -e "$T/thumbs/broken.png" ]
check "thumb: report has one line per model" [ "$(wc -l <"$T/thumbs/report.jsonl")" = 4 ]
check "thumb: report says ok for the good ones" [ "$(grep -c '"status":"ok"' "$T/thumbs/report.jsonl")" = 3 ]
check "thumb: report names the broken model, its status and error" \
	grep -q '"file":"[^"]*broken.stl","output":null,"status":"invalid","ms":[0-9.]*,"error":"400 ' "$T/thumbs/report.jsonl"
check "thumb: report is in input order" sh -c "head -n 1 '$T/thumbs/report.jsonl' | grep -q cube.obj"
check "thumb: plain progress lines when stderr is not a terminal" grep -q '^umbra-render: \[4/4\]' "$T/thumb.err"

# ---- thumb: a glTF whose material uses an extension umbra does not do: named in the report ----
python3 - "$T/models/coat.gltf" <<'PY'
import base64, json, struct, sys
pos = struct.pack('<9f', -1, 0, 0, 1, 0, 0, 0, 1, 0)
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
     "extensionsUsed": ["KHR_materials_iridescence"],
     "materials": [{"extensions": {"KHR_materials_iridescence": {"iridescenceFactor": 1}}}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
     "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64," + base64.b64encode(pos).decode()}],
     "bufferViews": [{"buffer": 0, "byteLength": 36}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, 0, 0], "max": [1, 1, 0]}]}
json.dump(g, open(sys.argv[1], "w"))
PY
cli thumb "$T/models/coat.gltf" "$T/models/cube.obj" -o "$T/thumbw/" --size 64 --no-progress 2>/dev/null
check "thumb: report carries a model's material warnings" \
	grep -q '"file":"[^"]*coat.gltf".*"warnings":"/objects/0: KHR_materials_iridescence: iridescence not drawn' "$T/thumbw/report.jsonl"
check "thumb: no warnings for a model without such data" grep -q '"file":"[^"]*cube.obj".*"warnings":null' "$T/thumbw/report.jsonl"
check "thumb: summary line" grep -q '3 ok, 1 invalid, 0 failed, 0 skipped of 4' "$T/thumb.err"

# ---- thumb: models with their files beside them (a .gltf's .bin and image, an .obj's .mtl) ----
# The farm reads what a model refers to from the model's own directory (that directory is the
# root: a reference above it is the job's 400). A red-textured glTF box must come out red, a
# blue-.mtl OBJ cube blue; an .obj whose .mtl is missing still renders, with a warning.
mkdir -p "$T/multi/tex"
python3 - "$T/multi" <<'PY'
import json, struct, sys, zlib
d = sys.argv[1]
def png(path, rgb, n=4):
    raw = b''.join(b'\0' + bytes(rgb + (255,)) * n for _ in range(n))
    ch = lambda k, b: struct.pack('>I', len(b)) + k + b + struct.pack('>I', zlib.crc32(k + b))
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + ch(b'IHDR', struct.pack('>IIBBBBB', n, n, 8, 6, 0, 0, 0))
                           + ch(b'IDAT', zlib.compress(raw)) + ch(b'IEND', b''))
png(d + '/tex/red.png', (255, 0, 0))
# a unit cube, 12 triangles, flat normals, uv 0
P, N = [], []
for ax in range(3):
    for s in (-1, 1):
        q = [[0, 0, 0] for _ in range(4)]
        for k, (a, b) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
            q[k][ax], q[k][(ax + 1) % 3], q[k][(ax + 2) % 3] = s, a, b
        tri = (0, 1, 2, 0, 2, 3) if s > 0 else (0, 2, 1, 0, 3, 2)
        for t in tri:
            P += [c * 0.5 for c in q[t]]
            n = [0, 0, 0]; n[ax] = s; N += n
nv = len(P) // 3
binary = struct.pack('<%df' % len(P), *P) + struct.pack('<%df' % len(N), *N) + bytes(8 * nv)
open(d + '/box data.bin', 'wb').write(binary)
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "material": 0}]}],
     "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
     "textures": [{"source": 0}], "images": [{"uri": "tex/red.png"}],
     "buffers": [{"byteLength": len(binary), "uri": "box%20data.bin"}],
     "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 12 * nv},
                     {"buffer": 0, "byteOffset": 12 * nv, "byteLength": 12 * nv},
                     {"buffer": 0, "byteOffset": 24 * nv, "byteLength": 8 * nv}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": nv, "type": "VEC3",
                    "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
                   {"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC3"},
                   {"bufferView": 2, "componentType": 5126, "count": nv, "type": "VEC2"}]}
json.dump(g, open(d + '/box.gltf', 'w'))
g["buffers"][0]["uri"] = "../box%20data.bin"
json.dump(g, open(d + '/tex/escape.gltf', 'w'))
PY
{ echo 'mtllib cube.mtl'; echo 'usemtl blue'; cat "$T/models/cube.obj"; } >"$T/multi/cube.obj"
printf 'newmtl blue\nKd 0 0 1\n' >"$T/multi/cube.mtl"
{ echo 'mtllib gone.mtl'; cat "$T/models/cube.obj"; } >"$T/multi/lost.obj"
cli thumb "$T/multi/box.gltf" "$T/multi/cube.obj" "$T/multi/lost.obj" "$T/multi/tex/escape.gltf" \
	-o "$T/mthumbs/" --size 64 --no-progress 2>"$T/mthumbs.err"
rc=$?
check "thumb multi-file: exit 2 (only the escaping glTF is invalid)" [ $rc = 2 ]
red=$($PNG tint "$T/mthumbs/box.png" 2>/dev/null | cut -d' ' -f1)
check "thumb multi-file: the .gltf with a separate .bin and PNG renders red (${red:-none} red pixels)" \
	[ "${red:-0}" -gt 300 ]
blue=$($PNG tint "$T/mthumbs/cube.png" 2>/dev/null | cut -d' ' -f2)
check "thumb multi-file: the .obj reads its .mtl: blue (${blue:-none} blue pixels)" [ "${blue:-0}" -gt 300 ]
check "thumb multi-file: an .obj without its .mtl renders, and the report says so" \
	sh -c "[ -s '$T/mthumbs/lost.png' ] && grep -q '\"file\":\"[^\"]*lost.obj\".*\"status\":\"ok\".*gone.mtl' '$T/mthumbs/report.jsonl'"
check "thumb multi-file: a reference above the model's directory is the job's 400" \
	grep -q '"file":"[^"]*escape.gltf".*"status":"invalid".*"error":"400 .*box%20data.bin' "$T/mthumbs/report.jsonl"

# --progress forces the bar (as on a terminal): done/total, images/s, ETA, on one line.
cli thumb "$T/models/cube.obj" "$T/models/tetra.stl" -o "$T/bar" --size 32 --progress 2>"$T/bar.err"
check "thumb --progress: a bar with done/total, images/s and ETA" \
	sh -c "grep -q '\[#*\] 2/2  [0-9.]* images/s  ETA' '$T/bar.err' && ! grep -q '^umbra-render: \[' '$T/bar.err'"

# The thumbnail's ground: the model's base is on it and its shadow darkens the white background
# below the model; transparent: the corners are alpha 0 and the shadow has alpha.
cli thumb "$T/models/cube.obj" -o "$T/tr" --size 64 --transparent --no-progress 2>/dev/null
rc=$?
check "thumb --transparent: exit 0" [ $rc = 0 ]
a=$($PNG px "$T/tr/cube.png" 0 0 2>/dev/null | cut -d' ' -f4)
check "thumb --transparent: corner alpha 0" [ "$a" = 0 ]
# WebP and AVIF thumbnails: lossless (the PNG thumbnail's pixels, alpha too; decoded by the system's
# libwebp and libavif's avifdec: tests/util/webp.py, avif.py) and lossy with --quality.
for f in webp:WebP:80 avif:avif:60; do
	ext=${f%%:*}; name=${f#*:}; name=${name%%:*}; q=${f##*:}
	cli thumb "$T/models/cube.obj" -o "$T/tr-$ext" --size 64 --transparent --format "$name" --no-progress 2>/dev/null
	check "thumb --format $name: DIR/NAME.$ext, lossless with alpha, the PNG thumbnail's pixels" sh -c \
		"[ \"\$(python3 tests/util/$ext.py info '$T/tr-$ext/cube.$ext' 2>&1)\" = '64 64 lossless alpha' ] &&
		 [ \"\$(python3 tests/util/$ext.py compare '$T/tr-$ext/cube.$ext' '$T/tr/cube.png' 2>&1)\" = 'inf 0' ]"
	cli thumb "$T/models/cube.obj" -o "$T/trq-$ext" --size 64 --format "$name" --quality "$q" --no-progress 2>/dev/null
	check "thumb --format $name --quality $q: lossy" [ "$(python3 tests/util/$ext.py info "$T/trq-$ext/cube.$ext" 2>&1)" = "64 64 lossy opaque" ]
done
cli thumb "$T/models/cube.obj" -o "$T/trq2" --quality 80 2>"$T/trq2.err"
rc=$?
check "thumb --quality without --format webp: refused (exit 1)" eval '[ $rc = 1 ] && grep -q "format webp" "$T/trq2.err"'
cli thumb "$T/models/cube.obj" -o "$T/trq3" --format jpeg 2>"$T/trq3.err"
rc=$?
check "thumb --format jpeg: refused (exit 1), naming the formats" eval '[ $rc = 1 ] && grep -q "png, webp, avif or exr" "$T/trq3.err"'

# ---- thumb --up: a Z-up model (a post 0.3 x 0.3 x 2 along Z, as CAD and 3D-printing STLs lie)
# stands up: its opaque pixels are taller than wide; without --up it lies on its side.
python3 - "$T/zup/post.stl" <<'PY'
import sys, os
os.makedirs(os.path.dirname(sys.argv[1]), exist_ok=True)
x, y, z = (-0.15, 0.15), (-0.15, 0.15), (0.0, 2.0)
c = [(x[i & 1], y[i >> 1 & 1], z[i >> 2]) for i in range(8)]
quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
out = ['solid post']
for a, b, cc, d in quads:
    for t in ((a, b, cc), (a, cc, d)):
        out += ['facet normal 0 0 0', ' outer loop'] + ['  vertex %g %g %g' % c[k] for k in t] + [' endloop', 'endfacet']
open(sys.argv[1], 'w').write('\n'.join(out + ['endsolid post', '']))
PY
cli thumb "$T/zup/post.stl" -o "$T/zup/up/" --up z --size 96 --transparent --no-progress 2>"$T/zup/up.err"
check "thumb --up z: exit 0" [ $? = 0 ]
wh=$($PNG opaque "$T/zup/up/post.png" 2>/dev/null || echo 0 0)
w=${wh% *} h=${wh#* }
check "thumb --up z: the Z-up post stands up (${w}x${h} px: height > 2 x width)" [ "$h" -gt $((2 * w)) ]
cli thumb "$T/zup/post.stl" -o "$T/zup/flat/" --size 96 --transparent --no-progress 2>/dev/null
wh=$($PNG opaque "$T/zup/flat/post.png" 2>/dev/null || echo 0 0)
w=${wh% *} h=${wh#* }
check "thumb without --up: the same post lies on its side (${w}x${h} px: wider than tall)" [ "$w" -gt "$h" ]
cli thumb "$T/zup/post.stl" -o "$T/zup/bad/" --up w 2>"$T/zup/bad.err"
rc=$?
check "thumb --up w: refused (exit 1), naming the axes" eval '[ $rc = 1 ] && grep -q "z y x -z -y -x" "$T/zup/bad.err"'
cli "$T/ground.json" -o "$T/zup/scene.png" --up z 2>"$T/zup/scene.err"
rc=$?
check "--up without thumb: refused, pointing to the model object's \"up\"" eval '[ $rc = 1 ] && grep -q "model object" "$T/zup/scene.err"'

# ---- farm inputs that are no model file: invalid (exit 2), not failed ----
mkdir -p "$T/notfiles/adir"
: >"$T/notfiles/empty.stl"
cli thumb "$T/notfiles/adir" "$T/notfiles/empty.stl" "$T/models/cube.obj" -o "$T/notfiles/out/" --size 32 \
	--no-progress 2>"$T/notfiles.err"
rc=$?
check "thumb with a directory and an empty file among the models: exit 2 (invalid input), not 1" [ $rc = 2 ]
check "thumb: the directory is reported invalid, saying it is a directory" \
	grep -q '"file":"[^"]*adir","output":null,"status":"invalid".*is a directory' "$T/notfiles/out/report.jsonl"
check "thumb: the empty file is reported invalid, saying it is empty" \
	grep -q '"file":"[^"]*empty.stl","output":null,"status":"invalid".*empty model file (0 bytes)' "$T/notfiles/out/report.jsonl"

# ---- the self-placing ground: its shadow appears under a floating box ----
# Orthographic view straight down (+x right, -z up) over x, z in [-3, 3] at 96 px: 16 px per
# unit. A unit box floats at y 3; the ground places itself at the box's base (y 2.5); the light
# travels along (1, -1, 0), so the shadow of the box (x -0.5..0.5, top at 3.5) covers x 0.5..1.5
# beyond the box: x = 1 is column 64. x = -2 (column 16) stays background.
ground_scene() { # $1: extra output members
	cat <<EOF2
{"width": 96, "height": 96,
 "camera": {"type": "orthographic", "position": [0, 10, 0], "target": [0, 0, 0], "up": [0, 0, -1], "height": 6},
 "environment": {"background": [1, 1, 1]},
 "objects": [
  {"shape": "plane", "placement": "ground", "material": {"shadow_catcher": true}},
  {"shape": "box", "transform": {"translation": [0, 3, 0]}}],
 "lights": [{"type": "directional", "direction": [1, -1, 0], "shadow": {"filter": "pcf"}}],
 "output": {"msaa": 1$1}}
EOF2
}
ground_scene "" >"$T/ground.json"
ground_scene ', "transparent": true' >"$T/ground-t.json"
cli "$T/ground.json" -o "$T/ground.png" 2>"$T/ground.err"
check "ground scene renders" [ $? = 0 ]
shadow=$($PNG px "$T/ground.png" 64 48 2>/dev/null | cut -d' ' -f1)
bg=$($PNG px "$T/ground.png" 16 48 2>/dev/null | cut -d' ' -f1)
check "ground: background stays white away from the box ($bg)" [ "${bg:-0}" = 255 ]
check "ground: the box's shadow darkens the ground next to it ($shadow)" [ "${shadow:-255}" -lt 200 ]
cli "$T/ground-t.json" -o "$T/ground-t.png" 2>/dev/null
sa=$($PNG px "$T/ground-t.png" 64 48 2>/dev/null | cut -d' ' -f4)
ba=$($PNG px "$T/ground-t.png" 16 48 2>/dev/null | cut -d' ' -f4)
check "ground, transparent: shadow has alpha ($sa), background none ($ba)" sh -c "[ '${sa:-0}' -gt 60 ] && [ '$ba' = 0 ]"
# -o NAME.webp: a lossless WebP (decoded by the system's libwebp: tests/util/webp.py) with the
# PNG's pixels, alpha included (other extensions: -o x.jpg below).
WEBP="python3 tests/util/webp.py"
cli "$T/ground-t.json" -o "$T/ground-t.webp" 2>/dev/null
check "-o .webp: a lossless WebP with alpha" [ "$($WEBP info "$T/ground-t.webp" 2>&1)" = "96 96 lossless alpha" ]
check "-o .webp: the transparent PNG's pixels exactly" [ "$($WEBP compare "$T/ground-t.webp" "$T/ground-t.png" 2>&1)" = "inf 0" ]
sed 's/"msaa": 1/"msaa": 1, "quality": 80/' "$T/ground.json" >"$T/ground-q.json"
cli "$T/ground-q.json" -o "$T/ground-q.png" 2>"$T/q.err"
rc=$?
check "quality with -o .png: exit 2 at /output/quality" eval '[ $rc = 2 ] && grep -q "/output/quality" "$T/q.err"'
cli "$T/ground-q.json" -o "$T/ground-q.webp" 2>/dev/null
check "quality with -o .webp: a lossy WebP" [ "$($WEBP info "$T/ground-q.webp" 2>&1)" = "96 96 lossy opaque" ]
cli "$T/ground-q.json" -o "$T/ground-q.avif" 2>/dev/null
check "quality with -o .avif: a lossy AVIF" [ "$(python3 tests/util/avif.py info "$T/ground-q.avif" 2>&1)" = "96 96 lossy opaque" ]
cli "$T/ground-t.json" -o "$T/ground-t.avif" 2>/dev/null
check "-o .avif: a lossless AVIF with the transparent PNG's pixels" \
	[ "$(python3 tests/util/avif.py compare "$T/ground-t.avif" "$T/ground-t.png" 2>&1)" = "inf 0" ]
# A model by `path`: only under --asset-root, never outside it.
mkdir -p "$T/assets"
printf 'v -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n' >"$T/assets/tri.obj"
sed 's|{"shape": "box", "transform": {"translation": \[0, 3, 0\]}}|{"shape": "model", "path": "tri.obj"}|' "$T/ground.json" >"$T/path.json"
cli "$T/path.json" -o "$T/path-none.png" 2>"$T/path-none.err"
rc=$?
check "a path model without --asset-root: exit 2 naming the member" eval '[ $rc = 2 ] && grep -q "/objects/1" "$T/path-none.err"'
cli "$T/path.json" -o "$T/path.png" --asset-root "$T/assets" 2>"$T/path.err"
check "a path model with --asset-root: exit 0, a PNG" eval '[ $? = 0 ] && [ "$($PNG size "$T/path.png" 2>/dev/null)" = "96 96" ]'
sed 's|"path": "tri.obj"|"path": "../ground.json"|' "$T/path.json" >"$T/escape.json"
cli "$T/escape.json" -o "$T/escape.png" --asset-root "$T/assets" 2>/dev/null
check "--asset-root: a path leaving it is exit 2" [ $? = 2 ]
cli "$T/ground.json" -o "$T/ground.jpg" 2>"$T/jpg.err"
rc=$?
check "-o x.jpg: exit 2, nothing written, the reason on stderr" \
	eval '[ $rc = 2 ] && [ ! -e "$T/ground.jpg" ] && grep -q "writes PNG (.png), EXR (.exr), WebP (.webp) or AVIF (.avif)" "$T/jpg.err"'

# ---- several scenes and a manifest in one process ----
mkdir -p "$T/scenes"
cp "$T/ground.json" "$T/scenes/a.json"
sed 's/"width": 96/"width": 80/' "$T/ground.json" >"$T/scenes/b.json"
sed 's/"direction": \[1, -1, 0\]/"direction": [0, 0, 0]/' "$T/ground.json" >"$T/scenes/bad.json"
cli "$T/scenes/a.json" "$T/scenes/b.json" -o "$T/out1" --no-progress 2>"$T/out1.err"
check "scenes: exit 0 when all render" [ $? = 0 ]
check "scenes: a.png 96x96" [ "$($PNG size "$T/out1/a.png" 2>/dev/null)" = "96 96" ]
check "scenes: b.png 80x96" [ "$($PNG size "$T/out1/b.png" 2>/dev/null)" = "80 96" ]
cli "$T/scenes/a.json" "$T/scenes/bad.json" "$T/scenes/b.json" -o "$T/out2/" --report "$T/out2.jsonl" --no-progress 2>/dev/null
check "scenes: one bad scene -> exit 2" [ $? = 2 ]
check "scenes: the others still rendered" sh -c "[ -s '$T/out2/a.png' ] && [ -s '$T/out2/b.png' ]"
check "scenes: --report names the problem's pointer" \
	grep -q '"status":"invalid".*/lights/0/direction' "$T/out2.jsonl"
printf '{"scene": "a.json", "output": "first.png"}\n\n{"scene": {"width": 32, "height": 16, "camera": {"position": [0, 0, 5]}, "objects": [{"shape": "sphere"}]}, "output": "inline.png"}\n' \
	>"$T/scenes/list.jsonl"
cli --manifest "$T/scenes/list.jsonl" -o "$T/out3" --no-progress 2>/dev/null
check "manifest: exit 0" [ $? = 0 ]
check "manifest: path scene relative to the manifest, named by output" [ "$($PNG size "$T/out3/first.png" 2>/dev/null)" = "96 96" ]
check "manifest: inline scene" [ "$($PNG size "$T/out3/inline.png" 2>/dev/null)" = "32 16" ]
check "manifest: report labels the inline line by its line number" grep -q 'list.jsonl:3' "$T/out3/report.jsonl"
printf '{"scene": "a.json", "outptu": "x.png"}\n' >"$T/scenes/badlist.jsonl"
cli --manifest "$T/scenes/badlist.jsonl" -o "$T/out4" --no-progress 2>"$T/out4.err"
check "manifest: a bad line -> exit 2 naming the line" sh -c "[ $? = 2 ] && grep -q 'badlist.jsonl:1' '$T/out4.err'"
cli "$T/scenes/a.json" "$T/scenes/b.json" 2>/dev/null
check "several scenes without -o DIR -> exit 1" [ $? = 1 ]

# ---- Ctrl-C: the renders in flight finish, the rest are skipped, no partial files ----
mkdir -p "$T/many"
i=0
while [ $i -lt 40 ]; do cp "$T/models/cube.obj" "$T/many/m$i.obj"; i=$((i + 1)); done
LD_PRELOAD="$PRELOAD" "$CLI" thumb "$T"/many/*.obj -o "$T/intr" --size 512 -j 1 --no-progress 2>"$T/intr.err" &
pid=$!
i=0
while ! grep -q '^umbra-render: \[1/40\]' "$T/intr.err" 2>/dev/null && [ $i -lt 1200 ]; do sleep 0.1; i=$((i + 1)); done
kill -INT $pid
wait $pid
rc=$?
okn=$(grep -c '"status":"ok"' "$T/intr/report.jsonl" 2>/dev/null || echo 0)
check "Ctrl-C: exit 130" [ $rc = 130 ]
check "Ctrl-C: some rendered, the rest skipped" sh -c "[ $okn -ge 1 ] && grep -q '\"status\":\"skipped\"' '$T/intr/report.jsonl'"
check "Ctrl-C: every ok line has its complete PNG, nothing else" \
	sh -c "[ \$(ls '$T/intr' | grep -c '\\.png\$') = $okn ] && ! ls '$T/intr' | grep -q tmp"
check "Ctrl-C: report lists all 40" [ "$(wc -l <"$T/intr/report.jsonl")" = 40 ]

# ---- --explain: the plan without rendering, and with =analyze the render's measures ----
printf '{"width": 48, "height": 48, "camera": {"position": [4, 3, 4], "target": [0, 0.8, 0]}, "objects": [{"shape": "plane", "size": [10, 10]}, {"shape": "sphere", "radius": 1, "transform": {"translation": [0, 1, 0]}}], "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3]}]}' >"$T/ex.json"
cli --explain "$T/ex.json" >"$T/ex.plan" 2>"$T/ex.err"; rc=$?
check "--explain: exit 0, a plan valid under api/explain.schema.json" sh -c \
	"[ $rc = 0 ] && python3 tests/http/explain_check.py plan '$T/ex.plan'"
cli --explain=analyze "$T/ex.json" -o "$T/ex.png" >"$T/exa.plan" 2>"$T/exa.err"; rc=$?
check "--explain=analyze: the image written, the plan analyzed with the render's counts" sh -c \
	"[ $rc = 0 ] && [ -s '$T/ex.png' ] && python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); t=d[\"totals\"]; a=d[\"actual\"]; sys.exit(not (d[\"analyzed\"] and all(t[k] == a[k] for k in (\"shadow_maps_drawn\", \"shadow_texels\", \"shadow_triangles\", \"camera_triangles\"))))' '$T/exa.plan'"
cli --explain=maybe "$T/ex.json" >/dev/null 2>&1; rc=$?
check "--explain=maybe: exit 1" [ $rc = 1 ]
cli --explain "$T/ex.json" "$T/ex.json" -o "$T/exdir/" >/dev/null 2>"$T/exb.err"; rc=$?
check "--explain with several scenes: exit 1, said why" sh -c "[ $rc = 1 ] && grep -q 'one scene' '$T/exb.err'"

echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
