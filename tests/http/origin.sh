#!/bin/sh
# tests/http/origin.sh — who may call the daemon from a browser (server/origin.c), with curl
# playing the browser's headers: the default Host rule on loopback (DNS rebinding: 421) and on
# 0.0.0.0 (any Host), --allowed-host, foreign Origins and Sec-Fetch-Site: cross-site refused
# (403 problem+json naming --cors-origin), --cors-origin's answers (Access-Control-Allow-Origin,
# Vary, Expose-Headers) and preflights, and the headers every answer and the playground carry.
# Uses tests/http/lib.sh; ends with "N passed, N failed".
SUITE=origin . tests/http/lib.sh

printf '{"width": 32, "height": 32, "camera": {"position": [0, 1, 4], "target": [0, 0, 0]},
 "objects": [{"shape": "box"}], "lights": [{"type": "directional", "direction": [-1, -2, -1]}],
 "output": {"msaa": 1}}' >"$T/s.json"
# detail NAME: the problem's detail; has NAME TEXT: the detail contains TEXT.
detail() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1])).get("detail", ""))' "$T/$1.body" 2>/dev/null; }
has() { case "$(detail "$1")" in *"$2"*) return 0 ;; esac; echo "# detail: $(detail "$1")"; return 1; }
# ptype NAME: the problem's type, less https://umbra.dev/problems/
ptype() { python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["type"].rsplit("/", 1)[-1])' "$T/$1.body" 2>/dev/null; }
# preflight NAME PATH ORIGIN [CURL ARGS...]: an OPTIONS as a browser sends it before a JSON POST.
preflight() {
	fn=$1; fp=$2; fo=$3; shift 3
	curl -s --max-time 30 -o "$T/$fn.body" -D "$T/$fn.hdr" -w '%{http_code}' -X OPTIONS -H "Origin: $fo" \
		-H 'Access-Control-Request-Method: POST' -H 'Access-Control-Request-Headers: content-type,x-priority' \
		-H 'Sec-Fetch-Mode: cors' "$@" "$URL$fp"
}
# renders NAME STATUS: umbra_requests_total of /v1/render with that status, in a fresh scrape.
renders() { get metrics /metrics >/dev/null; metric "umbra_requests_total{route=\"/v1/render\",status=\"$1\"}"; }

"$UMBRAD" --cors-origin 'https://app.example.com/path' >"$T/f1.out" 2>&1; rc=$?
check "--cors-origin with a path: exit 2 naming the flag" sh -c "[ $rc = 2 ] && grep -q -- '--cors-origin' '$T/f1.out'"
"$UMBRAD" --cors-origin null >"$T/f2.out" 2>&1; rc=$?
check "--cors-origin null: exit 2" [ $rc = 2 ]
"$UMBRAD" --allowed-host 'render.example:8080' >"$T/f3.out" 2>&1; rc=$?
check "--allowed-host with a port: exit 2 naming the flag" sh -c "[ $rc = 2 ] && grep -q -- '--allowed-host' '$T/f3.out'"
"$UMBRAD" --help >"$T/help.out" 2>&1
check "--help lists --cors-origin and --allowed-host" sh -c "grep -q -- '--cors-origin LIST' '$T/help.out' && grep -q -- '--allowed-host LIST' '$T/help.out'"

# ==== defaults, on loopback ====
start def --workers 1 || { finish; exit 1; }
DEF=$PID
PORT=$(cat "$T/def.port")
c=$(post plain "$T/s.json"); check "no Origin (curl): 200" [ "$c" = 200 ]
check "no Origin: no Access-Control-Allow-Origin, no Vary: Origin" \
	sh -c "[ -z '$(hdr plain Access-Control-Allow-Origin)' ] && [ '$(hdr plain Vary)' = 'Accept, Prefer' ]"
n200=$(renders 200)
c=$(post foreign "$T/s.json" -H 'Origin: https://evil.example' -H 'Sec-Fetch-Site: cross-site' -H 'Sec-Fetch-Mode: cors')
check "foreign Origin: 403" [ "$c" = 403 ]
check "foreign Origin: problem+json" problem foreign 403 ""
check "foreign Origin: type origin-not-allowed" [ "$(ptype foreign)" = origin-not-allowed ]
check "foreign Origin: the detail names --cors-origin and the origin" has foreign '--cors-origin https://evil.example'
check "foreign Origin: no Access-Control-Allow-Origin" [ -z "$(hdr foreign Access-Control-Allow-Origin)" ]
check "foreign Origin: nothing rendered" [ "$(renders 200)" = "$n200" ]
check "foreign Origin: the access log says why" grep -q 'POST /v1/render 403 .*--cors-origin' "$T/def.log"
# A multipart form, as an HTML form on another site sends it (no preflight, Origin only).
c=$(curl -s --max-time 30 -o "$T/form.body" -D "$T/form.hdr" -w '%{http_code}' -H 'Origin: http://127.0.0.1:1' \
	-H 'Sec-Fetch-Site: same-site' -H 'Sec-Fetch-Mode: navigate' -F "scene=<$T/s.json" "$URL/v1/render")
check "a form from another port of the same host: 403" sh -c "[ $c = 403 ] && [ '$(ptype form)' = origin-not-allowed ]"
# The refusal is answered once the body is read: the connection stays usable (a browser still
# sending its form sees the 403, not a reset).
codes=$(curl -s --max-time 30 -H 'Content-Type: application/json' -H 'Origin: https://evil.example' --data-binary "@$T/s.json" \
	-w '%{http_code}:%{num_connects} ' -o /dev/null "$URL/v1/render" -o /dev/null "$URL/v1/render")
check "a refused POST keeps the connection alive ($codes)" [ "$codes" = "403:1 403:0 " ]
c=$(post own "$T/s.json" -H "Origin: http://127.0.0.1:$PORT" -H 'Sec-Fetch-Site: same-origin')
check "the daemon's own origin (the playground): 200" [ "$c" = 200 ]
c=$(post own2 "$T/s.json" -H "Host: localhost:$PORT" -H "Origin: http://localhost:$PORT")
check "own origin by another loopback name: 200" [ "$c" = 200 ]
c=$(post own3 "$T/s.json" -H "Origin: http://localhost:$PORT")
check "Origin localhost on Host 127.0.0.1: another origin, 403" [ "$c" = 403 ]
c=$(post xsite "$T/s.json" -H 'Sec-Fetch-Site: cross-site' -H 'Sec-Fetch-Mode: no-cors')
check "Sec-Fetch-Site: cross-site without Origin: 403" sh -c "[ $c = 403 ] && [ '$(ptype xsite)' = origin-not-allowed ]"
c=$(get link / -H 'Sec-Fetch-Site: cross-site' -H 'Sec-Fetch-Mode: navigate')
check "a link to the playground from another site (GET, navigate): 200" [ "$c" = 200 ]
c=$(preflight pf /v1/render https://evil.example)
check "preflight from a foreign origin: 403" sh -c "[ $c = 403 ] && [ -z '$(hdr pf Access-Control-Allow-Origin)' ]"
c=$(curl -s -o /dev/null -D "$T/opt.hdr" -w '%{http_code}' -X OPTIONS "$URL/v1/render")
check "OPTIONS without Origin: 204, Allow: POST, OPTIONS" sh -c "[ $c = 204 ] && [ '$(hdr opt Allow)' = 'POST, OPTIONS' ]"
c=$(curl -s -o /dev/null -w '%{http_code}' -X OPTIONS "$URL/nope")
check "OPTIONS on an unknown path: 404" [ "$c" = 404 ]

# -- Host (DNS rebinding): loopback names only
c=$(get rebind /v1/info -H "Host: evil.example:$PORT")
check "Host evil.example on a loopback daemon: 421" [ "$c" = 421 ]
check "Host refused: problem+json, type host-not-allowed" eval 'problem rebind 421 "" && [ "$(ptype rebind)" = host-not-allowed ]'
check "Host refused: the detail names --allowed-host" has rebind '--allowed-host evil.example'
c=$(post rebind2 "$T/s.json" -H "Host: evil.example:$PORT" -H "Origin: http://evil.example:$PORT")
check "a rebinding page's same-origin render: 421" [ "$c" = 421 ]
for h in "localhost:$PORT" "127.0.0.1:$PORT" "[::1]:$PORT" localhost LOCALHOST.; do
	c=$(get host /v1/info -H "Host: $h")
	check "Host $h: 200" [ "$c" = 200 ]
done
c=$(get probe /readyz -H 'Host: umbra-lb'); check "/readyz answers any Host (balancers' checks)" [ "$c" = 200 ]
c=$(get probe2 /healthz -H 'Host: umbra-lb'); check "/healthz answers any Host" [ "$c" = 200 ]
c=$(get probe3 /metrics -H 'Host: umbra-lb'); check "/metrics does not: 421" [ "$c" = 421 ]

# -- what every answer tells a browser
c=$(get page /)
csp=$(hdr page Content-Security-Policy)
echo "# CSP: $csp"
check "GET /: CSP default-src 'self', frame-ancestors 'none'" sh -c "case \"\$1\" in *\"default-src 'self'\"*\"frame-ancestors 'none'\"*) exit 0 ;; esac; exit 1" - "$csp"
check "GET /: CSP has no 'unsafe-inline', scripts by hash" sh -c "case \"\$1\" in *unsafe-inline*) exit 1 ;; *\"script-src 'sha256-\"*) exit 0 ;; esac; exit 1" - "$csp"
check "GET /: nosniff, Referrer-Policy no-referrer" sh -c "[ '$(hdr page X-Content-Type-Options)' = nosniff ] && [ '$(hdr page Referrer-Policy)' = no-referrer ]"
c=$(get pg /playground); check "GET /playground: the same CSP" [ "$(hdr pg Content-Security-Policy)" = "$csp" ]
bad=""
for n in plain foreign rebind opt info404; do
	[ $n = info404 ] && get info404 /nope >/dev/null
	[ "$(hdr $n X-Content-Type-Options)" = nosniff ] || bad="$bad $n"
	[ "$(hdr $n Content-Security-Policy)" = "default-src 'none'; frame-ancestors 'none'" ] || bad="$bad $n(csp)"
done
check "nosniff and CSP default-src 'none' on a render, a 403, a 421, an OPTIONS, a 404${bad:+ (not:$bad)}" [ -z "$bad" ]
stop def $DEF

# ==== --cors-origin and --allowed-host ====
start cors --workers 1 --cors-origin 'https://app.example.com, http://tool.example:8000' \
	--allowed-host 'render.example,127.0.0.1' || { finish; exit 1; }
CORS=$PID
c=$(post app "$T/s.json" -H 'Origin: https://app.example.com' -H 'Sec-Fetch-Site: cross-site' -H 'Sec-Fetch-Mode: cors')
check "allowed origin: 200" [ "$c" = 200 ]
check "allowed origin: Access-Control-Allow-Origin echoes it" [ "$(hdr app Access-Control-Allow-Origin)" = https://app.example.com ]
check "allowed origin: Vary: Accept, Prefer, Origin" [ "$(hdr app Vary)" = "Accept, Prefer, Origin" ]
eh=$(hdr app Access-Control-Expose-Headers)
check "allowed origin: ETag, Server-Timing, Retry-After, X-Request-Id, Umbra-Warnings exposed ($eh)" sh -c '
	for h in ETag Server-Timing Retry-After X-Request-Id Umbra-Warnings; do
		case ", $1," in *", $h,"*) ;; *) exit 1 ;; esac
	done' - "$eh"
check "allowed origin: Timing-Allow-Origin" [ "$(hdr app Timing-Allow-Origin)" = https://app.example.com ]
check "allowed origin: a PNG" [ "$(png_size "$T/app.body")" = 32x32 ]
c=$(post tool "$T/s.json" -H 'Origin: http://tool.example:8000')
check "second listed origin (with a port): 200 with its ACAO" sh -c "[ $c = 200 ] && [ '$(hdr tool Access-Control-Allow-Origin)' = 'http://tool.example:8000' ]"
c=$(post other "$T/s.json" -H 'Origin: https://other.example')
check "unlisted origin: 403 naming --cors-origin" sh -c "[ $c = 403 ] && [ -z '$(hdr other Access-Control-Allow-Origin)' ]"
check "unlisted origin: the detail names the flag" has other '--cors-origin https://other.example'
c=$(post xs "$T/s.json" -H 'Sec-Fetch-Site: cross-site')
check "cross-site without Origin, a list set: 403" [ "$c" = 403 ]
c=$(post none "$T/s.json"); check "no Origin: 200, Vary: Accept, Prefer, Origin" sh -c "[ $c = 200 ] && [ '$(hdr none Vary)' = 'Accept, Prefer, Origin' ]"
c=$(preflight pfa /v1/render https://app.example.com -H 'Access-Control-Request-Private-Network: true')
check "preflight from an allowed origin: 204" [ "$c" = 204 ]
check "preflight: Access-Control-Allow-Origin" [ "$(hdr pfa Access-Control-Allow-Origin)" = https://app.example.com ]
check "preflight: Allow-Methods POST" [ "$(hdr pfa Access-Control-Allow-Methods)" = POST ]
ah=$(hdr pfa Access-Control-Allow-Headers)
check "preflight: Allow-Headers has Content-Type, If-None-Match, X-Priority, Accept, X-Request-Id ($ah)" sh -c '
	for h in Content-Type If-None-Match X-Priority Accept X-Request-Id; do
		case ", $1," in *", $h,"*) ;; *) exit 1 ;; esac
	done' - "$ah"
check "preflight: Max-Age" sh -c "[ '$(hdr pfa Access-Control-Max-Age)' -gt 0 ]"
check "preflight: Allow-Private-Network when asked" [ "$(hdr pfa Access-Control-Allow-Private-Network)" = true ]
c=$(preflight pfi /v1/info https://app.example.com)
check "preflight on /v1/info: Allow-Methods GET, HEAD" sh -c "[ $c = 204 ] && [ '$(hdr pfi Access-Control-Allow-Methods)' = 'GET, HEAD' ]"
c=$(preflight pfo /v1/render https://other.example); check "preflight from an unlisted origin: 403" [ "$c" = 403 ]
c=$(get h1 /v1/info -H 'Host: render.example:8080'); check "--allowed-host: a listed name with a port: 200" [ "$c" = 200 ]
c=$(get h2 /v1/info -H 'Host: localhost'); check "--allowed-host replaces the default: localhost 421" [ "$c" = 421 ]
c=$(get h3 /v1/info -H 'Host: evil.example'); check "--allowed-host: an unlisted name 421 naming the flag" sh -c "[ $c = 421 ] && [ '$(ptype h3)' = host-not-allowed ]"
stop cors $CORS

# ==== 0.0.0.0 (as behind a balancer): any Host; --cors-origin * ====
start wide --workers 1 --listen 0.0.0.0:0 --cors-origin '*' || { finish; exit 1; }
WIDE=$PID
c=$(get w1 /v1/info -H 'Host: render.internal.example'); check "0.0.0.0: any Host by default" [ "$c" = 200 ]
c=$(post w2 "$T/s.json" -H 'Origin: https://anyone.example' -H 'Sec-Fetch-Site: cross-site')
check "--cors-origin *: any origin, echoed" sh -c "[ $c = 200 ] && [ '$(hdr w2 Access-Control-Allow-Origin)' = https://anyone.example ]"
c=$(post w3 "$T/s.json" -H 'Sec-Fetch-Site: cross-site'); check "--cors-origin *: cross-site without Origin: 200" [ "$c" = 200 ]
stop wide $WIDE

finish
