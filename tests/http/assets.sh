#!/bin/sh
# tests/http/assets.sh — models made of several files, and the texture limit, against a live
# umbrad: a .gltf with its .bin and PNG by `path` under --asset-root and as multipart parts
# named by their URI, an .obj with its .mtl and map_Kd texture, an inline .obj whose .mtl is
# missing (Umbra-Warnings, also as a lone part), an .obj whose texture is missing (200 and the
# same warning by path and by multipart), a .glb misnamed .stl (read as glb, warned), an inline
# .gltf needing its .bin (400), a missing .bin and a "../" URI (400 at the model's member), 20
# textures under the default limit (200) and over --max-textures 4 (422 at /objects/N).
# The quad's texture is red on its left half, blue on its right: the image must be too.
. tests/http/lib.sh

A=$T/assets
python3 tests/http/gen_assets.py "$A" || { nok "generate the assets"; finish; exit 1; }
PNGPY=tests/cli/png.py

# scene FILE MODEL_MEMBERS [EXTRA_OBJECTS_FIRST]: a camera looking at the quad from +Z.
scene() {
	cat >"$1" <<EOF
{"width": 64, "height": 64, "camera": {"position": [0, 0, 2.5], "target": [0, 0, 0], "fov_y": 60},
 "environment": {"ambient": {"sky": [1, 1, 1], "ground": [1, 1, 1], "intensity": 1}},
 "objects": [$3{"shape": "model", $2}],
 "lights": [{"type": "directional", "direction": [0, 0, -1], "intensity": 2}]}
EOF
}
# halves NAME: the left of the quad is red, the right blue (the texture, not the default grey).
halves() {
	l=$(python3 $PNGPY px "$T/$1.body" 16 32) && r=$(python3 $PNGPY px "$T/$1.body" 48 32) || return 1
	set -- $l $r
	[ "$1" -gt 200 ] && [ "$2" -lt 120 ] && [ "$3" -lt 120 ] && [ "$5" -lt 120 ] && [ "$6" -lt 120 ] && [ "$7" -gt 200 ] ||
		{ echo "# left $l right $r"; return 1; }
}
# answered CODE STATUS NAME POINTER: CODE is STATUS and NAME.body the problem at POINTER.
answered() { [ "$1" = "$2" ] && problem "$3" "$2" "$4"; }
detail_has() { python3 -c 'import json,sys; sys.exit(0 if sys.argv[2] in json.load(open(sys.argv[1]))["detail"] else 1)' "$T/$1.body" "$2"; }
# multipart NAME SCENE PARTS...: POST multipart/form-data; prints the status.
multipart() {
	mn=$1; ms=$2; shift 2
	set -- -F "scene=@$ms;type=application/json" "$@"
	curl -s --max-time 120 -o "$T/$mn.body" -D "$T/$mn.hdr" -w '%{http_code}' "$@" "$URL/v1/render"
}

start assets --asset-root "$A" || { finish; exit 1; }
MAIN=$PID

scene "$T/gltf.json" '"path": "quad.gltf"'
check "gltf + bin + png by path: 200" [ "$(post gltf "$T/gltf.json")" = 200 ]
check "gltf by path: the texture's halves (red left, blue right)" halves gltf
scene "$T/sub.json" '"path": "sub/quad.gltf"'
check "gltf whose URIs climb to its parent folder, inside the root: 200" [ "$(post sub "$T/sub.json")" = 200 ]
check "gltf in a subfolder: the texture's halves" halves sub

scene "$T/mp.json" '"part": "model", "format": "gltf"'
code=$(multipart mp "$T/mp.json" -F "model=@$A/quad.gltf" -F "quad.bin=@$A/quad.bin" -F "halves.png=@$A/halves.png")
check "gltf as multipart, its files as parts named by their URI: 200" [ "$code" = 200 ]
check "gltf by multipart: the texture's halves" halves mp
code=$(multipart mpmiss "$T/mp.json" -F "model=@$A/quad.gltf" -F "halves.png=@$A/halves.png")
check "multipart without the .bin part: 400 at /objects/0/part" answered "$code" 400 mpmiss /objects/0/part
check "multipart without the .bin part: the detail names quad.bin" detail_has mpmiss quad.bin

scene "$T/obj.json" '"path": "box.obj"'
check "obj + mtl + map_Kd by path: 200" [ "$(post obj "$T/obj.json")" = 200 ]
check "obj by path: the texture's halves" halves obj
sed -i 's/"format": "gltf"/"format": "obj"/' "$T/mp.json"
code=$(multipart objmp "$T/mp.json" -F "model=@$A/box.obj" -F "box.mtl=@$A/box.mtl" -F "halves.png=@$A/halves.png")
check "obj + mtl + texture as multipart parts: 200" [ "$code" = 200 ]
check "obj by multipart: the texture's halves" halves objmp
b64=$(base64 -w0 "$A/box.obj")
scene "$T/inline.json" "\"data\": \"$b64\", \"format\": \"obj\""
check "inline obj whose .mtl is not in the request: 200" [ "$(post inline "$T/inline.json")" = 200 ]
warned() { hdr "$1" Umbra-Warnings | grep -q "$2"; }
check "inline obj without its .mtl: Umbra-Warnings names box.mtl" warned inline box.mtl
code=$(multipart objalone "$T/mp.json" -F "model=@$A/box.obj")
check "obj as the only part (no .mtl part): 200" [ "$code" = 200 ]
check "obj without its .mtl part: Umbra-Warnings names box.mtl" warned objalone box.mtl
code=$(multipart objnotex "$T/mp.json" -F "model=@$A/box.obj" -F "box.mtl=@$A/box.mtl")
check "obj + mtl parts without the texture part: 200" [ "$code" = 200 ]
check "obj without its texture part: Umbra-Warnings names halves.png" warned objnotex halves.png
# An .obj whose .mtl names a missing texture: the same answer by path and by multipart (and in
# the farm): 200, drawn without it, Umbra-Warnings naming it (by path it was a 400).
scene "$T/notex.json" '"path": "notex.obj"'
code=$(post notexpath "$T/notex.json")
check "obj by path whose .mtl names a missing texture: 200 (was 400)" [ "$code" = 200 ]
check "obj by path, missing texture: Umbra-Warnings names gone.png and says it cannot be read" \
	sh -c "grep -i '^Umbra-Warnings:' '$T/notexpath.hdr' | grep -q 'texture \"gone.png\" cannot be read'"
code=$(multipart notexmp "$T/mp.json" -F "model=@$A/notex.obj" -F "notex.mtl=@$A/notex.mtl")
check "the same obj by multipart without the texture: 200" [ "$code" = 200 ]
check "the same obj by multipart: Umbra-Warnings names gone.png" warned notexmp 'texture "gone.png"'
# The bytes decide the format: a .glb named .stl is read as glb, and the answer says so.
scene "$T/misnamed.json" '"path": "quadglb.stl"'
code=$(post misnamed "$T/misnamed.json")
check "a .glb named .stl by path: 200 (was read as STL: 400)" [ "$code" = 200 ]
check "a .glb named .stl: drawn as the glb (the texture's halves)" halves misnamed
check "a .glb named .stl: Umbra-Warnings names both formats" warned misnamed 'glb file by its bytes, not stl'
scene "$T/misnamedf.json" '"path": "quad.gltf", "format": "glb"'
code=$(post misnamedf "$T/misnamedf.json")
check "a .gltf sent with format glb: 200, read as gltf, warned" sh -c "[ '$code' = 200 ] && grep -i '^Umbra-Warnings:' \
	'$T/misnamedf.hdr' | grep -q 'gltf file by its bytes, not glb'"

scene "$T/gltfinline.json" "\"data\": \"$(base64 -w0 "$A/quad.gltf")\", \"format\": \"gltf\""
code=$(post gltfinline "$T/gltfinline.json")
check "inline gltf whose .bin is a separate file: 400 at /objects/0/data" answered "$code" 400 gltfinline /objects/0/data
check "inline gltf: the detail names quad.bin and says how to send it" detail_has gltfinline "multipart"

scene "$T/missing.json" '"path": "missing.gltf"'
code=$(post missing "$T/missing.json")
check "a missing .bin: 400 at /objects/0/path" answered "$code" 400 missing /objects/0/path
check "a missing .bin: the detail names nothing.bin" detail_has missing nothing.bin
scene "$T/escape.json" '"path": "escape.gltf"'
code=$(post escape "$T/escape.json")
check "a ../ URI above the root: 400 at /objects/0/path" answered "$code" 400 escape /objects/0/path
check "a ../ URI: the detail says it leaves the root" detail_has escape "leaves the asset root"

mkfifo "$A/pipe.bin"
ln -s /etc/passwd "$A/link.bin"
sed 's/quad\.bin/pipe.bin/' "$A/quad.gltf" >"$A/fifo.gltf"
sed 's/quad\.bin/link.bin/' "$A/quad.gltf" >"$A/link.gltf"
scene "$T/fifo.json" '"path": "fifo.gltf"'
code=$(post fifo "$T/fifo.json")
check "a .bin that is a FIFO: 400 at once at /objects/0/path" answered "$code" 400 fifo /objects/0/path
check "a FIFO .bin: the detail says it is not a regular file" detail_has fifo "not a regular file"
scene "$T/link.json" '"path": "link.gltf"'
code=$(post link "$T/link.json")
check "a .bin that is a symbolic link out of the root: 400 at /objects/0/path" answered "$code" 400 link /objects/0/path
check "a linked-out .bin: the detail says it leaves the root" detail_has link "leaves the asset root"

scene "$T/many.json" '"path": "many.gltf"' '{"shape": "plane", "size": [4, 4], "transform": {"translation": [0, 0, -1]}}, '
check "20 textures under the default limit: 200" [ "$(post many "$T/many.json")" = 200 ]
get info /v1/info >/dev/null
check "/v1/info: max_textures is the default 256 capped by device_max_textures (over 20)" \
	python3 -c 'import json,sys; l=json.load(open(sys.argv[1]))["limits"]; d=l["device_max_textures"]; sys.exit(0 if d >= 20 and l["max_textures"] == min(256, d) else 1)' "$T/info.body"
stop assets "$MAIN"

start few --asset-root "$A" --max-textures 4 || { finish; exit 1; }
code=$(post few "$T/many.json")
check "20 textures over --max-textures 4: 422 at /objects/1 (the model)" answered "$code" 422 few /objects/1
get info /v1/info >/dev/null
check "/v1/info says max_textures 4" \
	python3 -c 'import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))["limits"]["max_textures"] == 4 else 1)' "$T/info.body"
stop few "$PID"
finish
