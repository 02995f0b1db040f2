#!/bin/sh
# tests/http/lib.sh — what the black-box daemon suites share: the set-up of tests/util/suite.sh
# (BUILD, SHARED, the daemon binary, ASan preloads, $T, ok/nok counting, finish) and helpers to
# start, stop and query daemons on loopback (ephemeral ports, --port-file).
# Sourced by tests/http/*.sh: `. tests/http/lib.sh`; the suite ends with `finish`.
SUITE=${SUITE:-http} . tests/util/suite.sh
REPS=500
[ -n "${ASAN:-}" ] && REPS=100
case "$BUILD" in *asan*) REPS=100 ;; esac
RSS_BOUND_KB=32768
if [ -n "$asan_rt" ]; then
	REPS=100
	# ASan holds freed memory in its quarantine (256 MiB by default): LeakSanitizer checks leaks.
	RSS_BOUND_KB=307200
fi

# ---- helpers ----

# start NAME FLAGS...: starts a daemon; sets PID and URL (and NAME.log). Waits for /readyz.
start() {
	name=$1; shift
	rm -f "$T/$name.port"
	LD_PRELOAD="$DAEMON_PRELOAD" "$UMBRAD" --listen 127.0.0.1:0 --port-file "$T/$name.port" "$@" 2>"$T/$name.log" &
	PID=$!
	PIDS="$PIDS $PID"
	i=0
	while [ ! -s "$T/$name.port" ]; do
		i=$((i + 1))
		if [ $i -gt $((START_TIMEOUT * 10)) ] || ! kill -0 "$PID" 2>/dev/null; then
			nok "start $name" "no port file; log:"; sed 's/^/# /' "$T/$name.log" | tail -n 20
			URL=""; return 1
		fi
		sleep 0.1
	done
	URL="http://127.0.0.1:$(cat "$T/$name.port")"
	FIRST_READY=""
	i=0
	while :; do
		code=$(curl -s -o /dev/null -D "$T/$name.ready.hdr" -w '%{http_code}' --max-time 5 "$URL/readyz")
		[ -z "$FIRST_READY" ] && FIRST_READY=$code && cp "$T/$name.ready.hdr" "$T/$name.first-ready.hdr"
		[ "$code" = 200 ] && break
		i=$((i + 1))
		if [ $i -gt $((START_TIMEOUT * 10)) ] || ! kill -0 "$PID" 2>/dev/null; then
			nok "start $name" "/readyz never 200 (last $code); log:"; sed 's/^/# /' "$T/$name.log" | tail -n 20
			return 1
		fi
		sleep 0.1
	done
	return 0
}

# stop NAME PID: SIGTERM, then the exit status must be 0 (clean drain, no validation messages).
stop() {
	kill -TERM "$2" 2>/dev/null
	wait "$2"
	rc=$?
	if [ "$rc" -eq 0 ]; then ok "$1 exits 0 after SIGTERM"; else
		nok "$1 exits 0 after SIGTERM" "exit $rc; log:"; grep -v ' info ' "$T/$1.log" | tail -n 20 | sed 's/^/# /'
	fi
}

# post NAME FILE [CURL ARGS...]: POST FILE to /v1/render; prints the status; NAME.body/.hdr.
post() {
	pn=$1; pf=$2; shift 2
	curl -s --max-time 120 -o "$T/$pn.body" -D "$T/$pn.hdr" -w '%{http_code}' \
		-H 'Content-Type: application/json' --data-binary "@$pf" "$@" "$URL/v1/render"
}
# get NAME PATH [CURL ARGS...]
get() {
	gn=$1; gp=$2; shift 2
	curl -s --max-time 30 -o "$T/$gn.body" -D "$T/$gn.hdr" -w '%{http_code}' "$@" "$URL$gp"
}
# hdr NAME HEADER: the header's value from NAME.hdr (the last answer in it).
hdr() {
	tr -d '\r' <"$T/$1.hdr" | grep -i "^$2:" | tail -n 1 | sed 's/^[^:]*: *//'
}
# png_size FILE: "WxH" when FILE is a PNG (signature + IHDR), else nothing.
png_size() {
	[ "$(od -An -tx1 -N8 "$1" 2>/dev/null | tr -d ' \n')" = 89504e470d0a1a0a ] || return 1
	[ "$(od -An -c -j12 -N4 "$1" | tr -d ' \n')" = IHDR ] || return 1
	set -- $(od -An -tu1 -j16 -N8 "$1")
	echo "$(( ($1 << 24) | ($2 << 16) | ($3 << 8) | $4 ))x$(( ($5 << 24) | ($6 << 16) | ($7 << 8) | $8 ))"
}
is_exr() { [ "$(od -An -tx1 -N4 "$1" 2>/dev/null | tr -d ' \n')" = 762f3101 ]; }
# problem NAME STATUS POINTER: NAME.body is problem+json with that status and pointer
# (POINTER "-" = any pointer member present).
problem() {
	ct=$(hdr "$1" Content-Type)
	case "$ct" in application/problem+json*) ;; *) echo "# content-type '$ct'"; return 1 ;; esac
	python3 - "$T/$1.body" "$2" "$3" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
ok = d.get("status") == int(sys.argv[2]) and all(k in d for k in ("type", "title", "detail", "pointer"))
if sys.argv[3] != "-":
    ok = ok and d.get("pointer") == sys.argv[3]
if not ok:
    print("# problem:", json.dumps(d))
sys.exit(0 if ok else 1)
PY
}
# metric NAME_WITH_LABELS: its value in the last /metrics scrape (T/metrics.body).
metric() {
	awk -v m="$1" '$1 == m { print $2; f = 1 } END { if (!f) print 0 }' "$T/metrics.body" | head -n 1
}
rss_kb() { awk '/^VmRSS:/ { print $2 }' "/proc/$1/status"; }
fd_count() { ls "/proc/$1/fd" | wc -l | tr -d ' '; }
