#!/bin/sh
# tests/http/thumbnail.sh — the thumbnail preset and the self-placing ground over HTTP: a model
# sent alone as multipart with "preset": "thumbnail" comes back framed on the preset's ground;
# scene members override the preset's; problems keep the scene's pointers; the ground's shadow
# shows under a floating box; GET / serves the playground. Uses tests/http/lib.sh.
. tests/http/lib.sh
PNG="python3 tests/cli/png.py"

# --max-rss 0: the reuse check below counts kept shadow maps, which a trim over the bound drops
start thumb --workers 2 --max-rss 0 || { echo "$pass passed, $fail failed"; exit 1; }
PID_THUMB=$PID

# A model with nothing else: 200, the preset's 512x512, content, a background that is white.
printf 'v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nv -1 0 1\nv 1 0 1\nv 1 2 1\nv -1 2 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n' >"$T/cube.obj"
code=$(curl -s --max-time 120 -o "$T/t1.body" -D "$T/t1.hdr" -w '%{http_code}' \
	-F 'scene={"preset": "thumbnail", "objects": [{"shape": "model", "part": "m", "format": "obj"}]};type=application/json' \
	-F "m=@$T/cube.obj" "$URL/v1/render")
check "preset thumbnail + multipart model: 200" [ "$code" = 200 ]
check "preset thumbnail: 512x512 PNG" [ "$(png_size "$T/t1.body")" = 512x512 ]
check "preset thumbnail: white background in the corner" [ "$($PNG px "$T/t1.body" 2 2 2>/dev/null)" = "255 255 255 255" ]
check "preset thumbnail: the model and its shadow (>50 colours)" [ "$($PNG distinct "$T/t1.body" 2>/dev/null || echo 0)" -gt 50 ]

# The scene's own members win: size, transparent background.
code=$(curl -s --max-time 120 -o "$T/t2.body" -D "$T/t2.hdr" -w '%{http_code}' \
	-F 'scene={"preset": "thumbnail", "width": 128, "height": 96, "output": {"transparent": true}, "objects": [{"shape": "model", "part": "m", "format": "obj"}]};type=application/json' \
	-F "m=@$T/cube.obj" "$URL/v1/render")
check "preset overridden: 128x96" sh -c "[ '$code' = 200 ] && [ '$(png_size "$T/t2.body")' = 128x96 ]"
check "preset overridden: transparent corner" [ "$($PNG px "$T/t2.body" 1 1 2>/dev/null | cut -d' ' -f4)" = 0 ]

# Problems: an unknown preset at /preset; a bad member of the scene at its own pointer.
printf '{"preset": "thumbnale", "objects": []}' >"$T/p1.json"
check "unknown preset: 400" [ "$(post p1 "$T/p1.json")" = 400 ]
check "unknown preset: problem names /preset" problem p1 400 /preset
printf '{"preset": "thumbnail", "objects": [{"shape": "box", "size": [1, 0, 1]}]}' >"$T/p2.json"
check "preset: a bad member of the scene: 400" [ "$(post p2 "$T/p2.json")" = 400 ]
check "preset: problem at /objects/0/size" problem p2 400 /objects/0/size
printf '{"camera": {"position": [0, 0, 5]}, "objects": [{"shape": "plane", "placement": "ground", "transform": {"translation": [0, 1, 0]}}]}' >"$T/p3.json"
check "ground with a transform: 400" [ "$(post p3 "$T/p3.json")" = 400 ]
check "ground with a transform: problem at /objects/0/transform" problem p3 400 /objects/0/transform

# The self-placing ground: a box floating at y 3, the ground at its base (2.5), a light along
# (1, -1, 0) seen from straight above (orthographic, 6 units over 96 px): its shadow covers x 0.5
# to 1.5 beside the box (column 64 at x = 1); x = -2 (column 16) stays background.
cat >"$T/ground.json" <<'EOF2'
{"width": 96, "height": 96,
 "camera": {"type": "orthographic", "position": [0, 10, 0], "target": [0, 0, 0], "up": [0, 0, -1], "height": 6},
 "environment": {"background": [1, 1, 1]},
 "objects": [
  {"shape": "plane", "placement": "ground", "material": {"shadow_catcher": true}},
  {"shape": "box", "transform": {"translation": [0, 3, 0]}}],
 "lights": [{"type": "directional", "direction": [1, -1, 0], "shadow": {"filter": "pcf"}}],
 "output": {"msaa": 1}}
EOF2
check "ground scene: 200" [ "$(post g "$T/ground.json")" = 200 ]
s=$($PNG px "$T/g.body" 64 48 2>/dev/null | cut -d' ' -f1)
b=$($PNG px "$T/g.body" 16 48 2>/dev/null | cut -d' ' -f1)
check "ground: the shadow beside the box ($s) is darker than the background ($b)" sh -c "[ '${s:-255}' -lt 200 ] && [ '${b:-0}' = 255 ]"

code=$(get pg /)
# A model part over 1 MB (a cube and a long comment) sent twice: the second request reuses the
# maps the first drew (nothing after a big input drops them; every map was dropped before).
# 5.5 MB: past 4 MiB a part's buffer is sized to the whole body at once (render_route.c), so
# the cube's faces, after the comment, come through that copy.
{ python3 -c 'import sys; sys.stdout.write(("# " + "x" * 1022 + "\n") * 5400)'; cat "$T/cube.obj"; } >"$T/bigcube.obj"
bigpost() {
	curl -s --max-time 120 -o "$T/$1.body" -w '%{http_code}' \
		-F 'scene={"preset": "thumbnail", "width": 64, "height": 64, "objects": [{"shape": "model", "part": "m", "format": "obj"}]};type=application/json' \
		-F "m=@$T/bigcube.obj" "$URL/v1/render"
}
c1=$(bigpost big1); get metrics /metrics >/dev/null; r1=$(metric umbra_shadow_maps_reused_total)
c2=$(bigpost big2); get metrics /metrics >/dev/null; r2=$(metric umbra_shadow_maps_reused_total)
check "a 5.5 MB model part sent again: 200 twice, the same image, its shadow maps reused ($r1 -> $r2)" \
	sh -c "[ '$c1 $c2' = '200 200' ] && cmp -s '$T/big1.body' '$T/big2.body' && [ '${r2:-0}' -gt '${r1:-0}' ]"

check "GET / serves the playground" sh -c "[ '$code' = 200 ] && grep -q '<title>umbra playground</title>' '$T/pg.body'"
check "GET /playground serves it too" [ "$(get pg2 /playground)" = 200 ]
stop thumb "$PID_THUMB"
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
