#!/bin/sh
# tests/http/cache.sh — cacheable renders: POST /v1/renders answers 303 to GET
# /v1/renders/{hash}.{ext}, whose hash is the canonical scene's (the same scene spelled otherwise
# gets the same name, a changed model another); the GET form answers from the bounded result
# cache with an immutable Cache-Control, 304 on If-None-Match, HEAD; an evicted image is
# rendered again from its kept scene; a POST with a matching If-None-Match is a 412. Then the
# same through a real shared cache, nginx with deploy/nginx/umbra-cache.conf (skipped when nginx
# is not installed): a repeated thumbnail is a HIT, a changed model a MISS. Uses tests/http/lib.sh.
. tests/http/lib.sh

# A cube model, a variant of it, and the thumbnail scene that frames it (multipart).
printf 'v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nv -1 0 1\nv 1 0 1\nv 1 2 1\nv -1 2 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n' >"$T/cube.obj"
sed 's/^v 1 2 1$/v 1 3 1/' "$T/cube.obj" >"$T/cube2.obj"
printf '{"preset": "thumbnail", "width": 128, "height": 128, "objects": [{"shape": "model", "part": "m", "format": "obj"}]}' >"$T/thumb.json"
# The same document spelled otherwise: members reordered, other whitespace, 128.0 for 128.
printf '{\n  "objects" : [ { "format":"obj", "part":"m", "shape":"model" } ],\n  "height" : 128.0,\n  "width" : 1.28e2,\n  "preset" : "thumbnail"\n}\n' >"$T/thumb2.json"

# renders NAME BASE SCENE MODEL [CURL ARGS...]: POST SCENE + MODEL (part m) to BASE/v1/renders;
# prints the status; NAME.hdr/.body.
renders() {
	rn=$1; rb=$2; rs=$3; rm_=$4; shift 4
	curl -s --max-time 120 -o "$T/$rn.body" -D "$T/$rn.hdr" -w '%{http_code}' "$@" \
		-F "scene=@$rs;type=application/json" -F "m=@$rm_;type=application/octet-stream" "$rb/v1/renders"
}
# fetch NAME URL [CURL ARGS...]
fetch() {
	fn=$1; fu=$2; shift 2
	curl -s --max-time 120 -o "$T/$fn.body" -D "$T/$fn.hdr" -w '%{http_code}' "$@" "$fu"
}
metric() { curl -s --max-time 10 "$URL/metrics" | awk -v m="$1" '$1 == m { print $2 }'; }

start cache --workers 2 --result-cache-mb 1 || { finish; exit 1; }
PID_CACHE=$PID

# ---- the daemon alone ----
c=$(renders p1 "$URL" "$T/thumb.json" "$T/cube.obj")
loc=$(hdr p1 Location); etag=$(hdr p1 ETag)
check "POST /v1/renders: 303 See Other" [ "$c" = 303 ]
check "Location is /v1/renders/{16 hex}.png ($loc)" sh -c "echo '$loc' | grep -Eq '^/v1/renders/[0-9a-f]{16}\.png\$'"
check "the 303's ETag names the Location's hash" [ "$etag" = "\"$(basename "$loc" .png)\"" ]
c=$(fetch g1 "$URL$loc")
check "GET the Location: 200 PNG 128x128" sh -c "[ '$c' = 200 ] && [ '$(png_size "$T/g1.body")' = 128x128 ]"
check "GET: the same ETag" [ "$(hdr g1 ETag)" = "$etag" ]
check "GET: Cache-Control public, max-age=31536000, immutable" [ "$(hdr g1 Cache-Control)" = "public, max-age=31536000, immutable" ]
c=$(fetch g304 "$URL$loc" -H "If-None-Match: $etag")
check "GET with If-None-Match: 304, no body" sh -c "[ '$c' = 304 ] && [ ! -s '$T/g304.body' ]"
c=$(curl -s --max-time 30 -I -o /dev/null -D "$T/ghead.hdr" -w '%{http_code} %{size_download}' "$URL$loc")
check "HEAD: 200 image/png, no body ($c)" sh -c "[ '$c' = '200 0' ] && [ '$(hdr ghead Content-Type)' = image/png ]"
c=$(renders p2 "$URL" "$T/thumb2.json" "$T/cube.obj")
check "re-serialized JSON (keys reordered, whitespace, 128.0): the same Location" sh -c "[ '$c' = 303 ] && [ '$(hdr p2 Location)' = '$loc' ]"
# Defaults written out: the ETag is of the parsed scene with its defaults filled.
printf '{"preset": "thumbnail", "width": 128, "height": 128, "objects": [{"shape": "model", "part": "m", "format": "obj", "cast_shadows": true, "transform": {"scale": [1, 1, 1]}}], "output": {"msaa": 4}, "camera": {"exposure": 0}}' >"$T/thumb3.json"
c=$(renders p2d "$URL" "$T/thumb3.json" "$T/cube.obj")
check "defaults written out (cast_shadows true, scale 1, msaa 4, exposure 0): the same Location" sh -c "[ '$c' = 303 ] && [ '$(hdr p2d Location)' = '$loc' ]"
sed 's/"exposure": 0/"exposure": 0.5/' "$T/thumb3.json" >"$T/thumb4.json"
c=$(renders p2e "$URL" "$T/thumb4.json" "$T/cube.obj")
check "a value that is not the default (exposure 0.5): another Location" sh -c "[ '$c' = 303 ] && [ '$(hdr p2e Location)' != '$loc' ]"
c=$(renders p3 "$URL" "$T/thumb.json" "$T/cube2.obj")
check "a changed model: another Location" sh -c "[ '$c' = 303 ] && [ -n '$(hdr p3 Location)' ] && [ '$(hdr p3 Location)' != '$loc' ]"
c=$(renders p412 "$URL" "$T/thumb.json" "$T/cube.obj" -H "If-None-Match: $etag")
check "POST with If-None-Match listing its ETag: 412 problem+json" sh -c "[ '$c' = 412 ] && grep -q precondition-failed '$T/p412.body'"
c=$(curl -s --max-time 120 -o "$T/r412.body" -w '%{http_code}' -H "If-None-Match: $etag" -F "scene=@$T/thumb2.json;type=application/json" \
	-F "m=@$T/cube.obj" "$URL/v1/render")
check "POST /v1/render, the same scene re-serialized, with that ETag: 412" [ "$c" = 412 ]
c=$(fetch g404 "$URL/v1/renders/0123456789abcdef.png")
check "GET of an unknown hash: 404 problem+json saying to POST again" sh -c "[ '$c' = 404 ] && grep -q 'POST the scene' '$T/g404.body'"
c=$(fetch gbad "$URL/v1/renders/xyz.png"); check "GET of a malformed name: 404" [ "$c" = 404 ]
c=$(fetch gext "$URL$(dirname "$loc")/$(basename "$loc" .png).exr"); check "GET with another format's extension: 404" [ "$c" = 404 ]
c=$(fetch gpost "$URL$loc" -X POST); check "POST on the GET form: 405" [ "$c" = 405 ]
# What the image leaves out is never silent: the GET form repeats the render's Umbra-Warnings.
printf '{"preset": "thumbnail", "width": 64, "height": 64, "objects": [{"shape": "box"}], "shadows": {"pcf_radius": 2}}' >"$T/warn.json"
curl -s --max-time 120 -o /dev/null -D "$T/w1.hdr" -H 'Content-Type: application/json' --data-binary "@$T/warn.json" "$URL/v1/renders" >/dev/null
c=$(fetch w2 "$URL$(hdr w1 Location)")
check "GET form: the render's Umbra-Warnings ($(hdr w2 Umbra-Warnings))" sh -c "[ '$c' = 200 ] && [ -n \"\$1\" ] && [ \"\$1\" = \"\$2\" ]" - "$(hdr w1 Umbra-Warnings)" "$(hdr w2 Umbra-Warnings)"
check "hits counted (umbra_result_cache_hits_total >= 3)" [ "$(metric umbra_result_cache_hits_total)" -ge 3 ]
check "misses counted" [ "$(metric umbra_result_cache_misses_total)" -ge 1 ]

# Eviction: three 1448x1448 EXRs (~0.5 MB each) in a 1 MB cache; the first is rendered again
# from its kept scene, to the same bytes.
for i in 1 2 3; do
	printf '{"width": 1448, "height": 1448, "camera": {"position": [3, 2, %d], "target": [0, 0, 0]}, "objects": [{"shape": "sphere"}], "lights": [{"type": "directional", "direction": [-1, -1, -1]}], "output": {"format": "exr"}}' "$((3 + i))" >"$T/big$i.json"
	curl -s --max-time 120 -o /dev/null -D "$T/b$i.hdr" -H 'Content-Type: application/json' --data-binary "@$T/big$i.json" "$URL/v1/renders" >/dev/null
	[ "$i" = 1 ] && fetch b1first "$URL$(hdr b1 Location)" >/dev/null
done
echo "# EXR of 1448x1448: $(wc -c <"$T/b1first.body") bytes"
check "three EXRs stored: .exr Locations" grep -qi 'location: /v1/renders/.*\.exr' "$T/b3.hdr"
again=$(metric umbra_result_cache_rendered_again_total)
c=$(fetch b1again "$URL$(hdr b1 Location)")
check "evicted image: rendered again from its kept scene (200)" [ "$c" = 200 ]
check "rendered again: the same bytes" cmp -s "$T/b1first.body" "$T/b1again.body"
check "umbra_result_cache_rendered_again_total counted it" [ "$(metric umbra_result_cache_rendered_again_total)" -gt "${again:-0}" ]
check "the cache stays within --result-cache-mb 1" [ "$(metric umbra_result_cache_bytes)" -le 1048576 ]

# ---- through nginx (deploy/nginx/umbra-cache.conf) ----
if ! command -v nginx >/dev/null 2>&1 && [ ! -x /usr/sbin/nginx ]; then
	echo "# nginx not installed (Debian: nginx-light): the shared-cache checks skipped"
else
	NGINX=$(command -v nginx || echo /usr/sbin/nginx)
	N="$T/nginx"; mkdir -p "$N/cache" "$N/logs"
	nport=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
	dport=${URL##*:}
	sed -e "s|server 127.0.0.1:8080;|server 127.0.0.1:$dport;|" -e "s|listen 8081;|listen 127.0.0.1:$nport;|" \
	    -e "s|/var/cache/nginx/umbra|$N/cache|" deploy/nginx/umbra-cache.conf >"$N/umbra-cache.conf"
	{
		[ "$(id -u)" = 0 ] && echo "user root root;"   # workers keep access to the mktemp directory
		cat <<EOF
worker_processes 1;
error_log $N/logs/error.log;
pid $N/nginx.pid;
events { worker_connections 64; }
http {
    access_log off;
    client_body_temp_path $N/client_body; proxy_temp_path $N/proxy;
    fastcgi_temp_path $N/fastcgi; uwsgi_temp_path $N/uwsgi; scgi_temp_path $N/scgi;
    include $N/umbra-cache.conf;
}
EOF
	} >"$N/nginx.conf"
	"$NGINX" -p "$N" -c "$N/nginx.conf" -e "$N/logs/error.log" -g 'daemon off;' 2>"$N/stderr" &
	NPID=$!
	PIDS="$PIDS $NPID"
	NURL="http://127.0.0.1:$nport"
	i=0
	while ! curl -s -o /dev/null --max-time 2 "$NURL/healthz"; do
		i=$((i + 1)); [ $i -gt 50 ] && break; sleep 0.1
	done
	check "nginx starts with deploy/nginx/umbra-cache.conf" curl -sf -o /dev/null --max-time 5 "$NURL/healthz" ||
		sed 's/^/# /' "$N/stderr" "$N/logs/error.log"
	# A fresh thumbnail (its own size: nothing of it in nginx's cache yet).
	sed 's/"width": 128/"width": 120/' "$T/thumb.json" >"$T/thumb3.json"
	c=$(renders n1 "$NURL" "$T/thumb3.json" "$T/cube.obj")
	nloc=$(hdr n1 Location)
	check "through nginx: POST /v1/renders 303" sh -c "[ '$c' = 303 ] && [ -n '$nloc' ]"
	c=$(fetch n2 "$NURL$nloc")
	check "through nginx: first GET 200, X-Cache-Status MISS" sh -c "[ '$c' = 200 ] && [ '$(hdr n2 X-Cache-Status)' = MISS ]"
	gets=$(curl -s "$URL/metrics" | awk '$1 ~ /^umbra_requests_total\{route="\/v1\/renders\/\{hash\}",status="200"\}$/ { print $2 }')
	c=$(fetch n3 "$NURL$nloc")
	check "through nginx: repeated GET is a HIT" sh -c "[ '$c' = 200 ] && [ '$(hdr n3 X-Cache-Status)' = HIT ]"
	check "through nginx: the HIT has the same bytes and ETag" sh -c "cmp -s '$T/n2.body' '$T/n3.body' && [ '$(hdr n3 ETag)' = '$(hdr n2 ETag)' ]"
	gets2=$(curl -s "$URL/metrics" | awk '$1 ~ /^umbra_requests_total\{route="\/v1\/renders\/\{hash\}",status="200"\}$/ { print $2 }')
	check "the HIT never reached umbrad ($gets -> $gets2 GETs answered)" [ "$gets" = "$gets2" ]
	c=$(renders n4 "$NURL" "$T/thumb3.json" "$T/cube2.obj")
	c2=$(fetch n5 "$NURL$(hdr n4 Location)")
	check "through nginx: a changed model is another Location and a MISS" sh -c "[ '$c' = 303 ] && [ '$(hdr n4 Location)' != '$nloc' ] && [ '$c2' = 200 ] && [ '$(hdr n5 X-Cache-Status)' = MISS ]"
	printf '{ "width":120, "objects":[{"part":"m","format":"obj","shape":"model"}], "preset":"thumbnail", "height":128 }' >"$T/thumb4.json"
	c=$(renders n6 "$NURL" "$T/thumb4.json" "$T/cube.obj")
	c2=$(fetch n7 "$NURL$(hdr n6 Location)")
	check "through nginx: the same thumbnail re-serialized: the same Location, a HIT" sh -c "[ '$(hdr n6 Location)' = '$nloc' ] && [ '$(hdr n7 X-Cache-Status)' = HIT ]"
	kill -TERM "$NPID" 2>/dev/null; wait "$NPID" 2>/dev/null
fi

stop cache "$PID_CACHE"
finish
