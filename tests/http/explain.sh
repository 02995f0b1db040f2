#!/bin/sh
# tests/http/explain.sh — the render plan over HTTP (server/explain.c): POST /v1/explain answers
# the plan of a scene as JSON valid under api/explain.schema.json, nothing rendered; a change of
# request moves it the documented way (a bigger output: a hard light's bigger map; a second
# request: its maps cached, none drawn); POST /v1/render?explain=1 answers multipart/mixed: the
# very image of the plain render and the plan with what the render measured, its counts equal
# to the plan's; errors as the render's. Uses tests/http/lib.sh, tests/http/explain_check.py.
. tests/http/lib.sh
CHECK="python3 tests/http/explain_check.py"

scene() { # scene SIZE: a hard spot (its map sized to the output) and a sphere over a ground
	cat <<EOF2
{"width": $1, "height": $1,
 "camera": {"type": "perspective", "position": [4, 3, 4], "target": [0, 0.8, 0], "up": [0, 1, 0], "fov_y": 40},
 "objects": [{"shape": "plane", "size": [10, 10]},
  {"shape": "sphere", "radius": 1, "transform": {"translation": [0, 1, 0]}}],
 "lights": [{"type": "spot", "position": [2, 4, 2], "direction": [-0.4, -1, -0.4], "intensity": 40}]}
EOF2
}
scene 24 >"$T/s24.json"
scene 192 >"$T/s192.json"
scene 64 >"$T/s64.json"
sed 's/"width": 64/"width": 0/' "$T/s64.json" >"$T/bad.json"
# explain NAME FILE [CURL ARGS...]: POST FILE to /v1/explain; prints the status.
explain() {
	en=$1; ef=$2; shift 2
	curl -s --max-time 120 -o "$T/$en.body" -D "$T/$en.hdr" -w '%{http_code}' \
		-H 'Content-Type: application/json' --data-binary "@$ef" "$@" "$URL/v1/explain"
}

start explain --workers 1 || { finish; exit 1; }
PID_EXPLAIN=$PID

c=$(explain e24 "$T/s24.json")
check "POST /v1/explain: 200 application/json" sh -c "[ '$c' = 200 ] && [ '$(hdr e24 Content-Type)' = application/json ]"
check "the plan is valid under api/explain.schema.json, not analyzed" $CHECK plan "$T/e24.body"
check "a plan is not cacheable: no-store, no ETag" sh -c "[ '$(hdr e24 Cache-Control)' = no-store ] && [ -z '$(hdr e24 ETag)' ]"
r24=$($CHECK get "$T/e24.body" shadow_maps.0.resolution)
explain e192 "$T/s192.json" >/dev/null
r192=$($CHECK get "$T/e192.body" shadow_maps.0.resolution)
check "a bigger output: the hard spot's map grows ($r24 -> $r192)" [ "${r192:-0}" -gt "${r24:-0}" ]
check "nothing rendered: the map still to draw" [ "$($CHECK get "$T/e24.body" shadow_maps.0.state)" = drawn ]

# The render with its plan (first: it draws the maps), then the plain render: the same image.
c=$(curl -s --max-time 120 -o "$T/ex.body" -D "$T/ex.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
	--data-binary "@$T/s64.json" "$URL/v1/render?explain=1")
check "?explain=1: 200" [ "$c" = 200 ]
check "?explain=1: not cacheable (no-store, no ETag)" sh -c "[ '$(hdr ex Cache-Control)' = no-store ] && [ -z '$(hdr ex ETag)' ]"
c=$(post plain "$T/s64.json")
check "plain render 200" [ "$c" = 200 ]
check "?explain=1: the image part is the plain render's bytes; the plan analyzed, valid, its counts the render's" \
	$CHECK multipart "$T/ex.body" "$(hdr ex Content-Type)" "$T/plain.body"
# The header form: Prefer: explain (RFC 7240), among other preferences; honoured, and said so.
c=$(curl -s --max-time 120 -o "$T/pf.body" -D "$T/pf.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
	-H 'Prefer: respond-async, explain' --data-binary "@$T/s64.json" "$URL/v1/render")
check "Prefer: explain: 200 multipart, Preference-Applied: explain, no-store" sh -c "[ '$c' = 200 ] && \
	[ '$(hdr pf Preference-Applied)' = explain ] && [ '$(hdr pf Cache-Control)' = no-store ] && [ -z '$(hdr pf ETag)' ]"
check "Prefer: explain: the same answer as ?explain=1 (the plain image, the plan analyzed, its counts the render's)" \
	$CHECK multipart "$T/pf.body" "$(hdr pf Content-Type)" "$T/plain.body"
check "a plain render: Vary: Accept, Prefer; no Preference-Applied" sh -c \
	"[ '$(hdr plain Vary)' = 'Accept, Prefer' ] && [ -z '$(hdr plain Preference-Applied)' ]"
c=$(curl -s --max-time 120 -o "$T/pu.body" -D "$T/pu.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
	-H 'Prefer: explain=sometimes' --data-binary "@$T/s64.json" "$URL/v1/render")
check "Prefer: explain=sometimes (unknown value): ignored as preferences are, the plain image" sh -c \
	"[ '$c' = 200 ] && [ -z '$(hdr pu Preference-Applied)' ] && cmp -s '$T/pu.body' '$T/plain.body'"
c=$(explain e2 "$T/s64.json")
check "explained again after the render: its map cached, none drawn" sh -c \
	"[ '$($CHECK get "$T/e2.body" shadow_maps.0.state)' = cached ] && [ '$($CHECK get "$T/e2.body" totals.shadow_maps_drawn)' = 0 ]"

# Errors: the render's own, and the parameter's.
c=$(explain bad "$T/bad.json"); check "an invalid scene: 400 at /width, as the render" eval '[ "$c" = 400 ] && problem bad 400 /width'
c=$(curl -s -o "$T/q.body" -D "$T/q.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
	--data-binary "@$T/s64.json" "$URL/v1/render?explain=maybe")
check "explain=maybe: 400 problem+json" eval '[ "$c" = 400 ] && problem q 400 ""'
c=$(curl -s -o "$T/q2.body" -D "$T/q2.hdr" -w '%{http_code}' -H 'Content-Type: application/json' \
	--data-binary "@$T/s64.json" "$URL/v1/renders?explain=1")
check "explain on /v1/renders: 400" [ "$c" = 400 ]
c=$(explain acc "$T/s64.json" -H 'Accept: image/png'); check "/v1/explain with Accept: image/png: 406" [ "$c" = 406 ]
c=$(get g /v1/explain); check "GET /v1/explain: 405 Allow: POST" sh -c "[ '$c' = 405 ] && [ '$(hdr g Allow)' = POST ]"
stop explain "$PID_EXPLAIN"
finish
