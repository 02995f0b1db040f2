#!/bin/sh
# deploy/check.sh — checks of deploy/ that need no cluster, container engine or systemd PID 1
# (make check-deploy). Prints "ok - x" / "FAIL - x" and last "N passed, N failed".
#   1. haproxy -c accepts deploy/haproxy.cfg.in filled with sample values;
#   2. systemd-analyze: the unit parses (offline security report; exposure printed);
#   3. the Dockerfile's runtime stage installs, directly or as dependencies, the package of
#      every shared library build/umbrad links, and every package it names exists in Debian;
#   4. the version is baked in without .git (make with UMBRA_VERSION= and with a VERSION file);
#   5. nginx -t accepts deploy/nginx/umbra-cache.conf inside a minimal nginx.conf (when nginx
#      is installed: nginx-light);
#   6. deploy/k8s/check.py (python3-yaml), and deploy/k8s/validate.mjs when
#      KUBERNETES_MODELS_DIR names a node_modules holding kubernetes-models and js-yaml.
BUILD=${BUILD:-build}
pass=0; fail=0
ok() { echo "ok - $1"; pass=$((pass + 1)); }
nok() { echo "FAIL - $1${2:+: $2}"; fail=$((fail + 1)); }
T=$(mktemp -d "${TMPDIR:-/tmp}/umbra-deploy.XXXXXX")
trap 'rm -rf "$T"' EXIT

# 1. HAProxy
if command -v haproxy >/dev/null; then
	python3 - "$T/haproxy.cfg" <<'PY'
import string, sys
t = string.Template(open("deploy/haproxy.cfg.in").read())
servers = "".join("    server umbra%d 10.0.0.%d:8080\n" % (i, 10 + i) for i in (1, 2, 3)).rstrip()
aff = "".join("    server umbra%d 10.0.0.%d:8080 track umbrad/umbra%d\n" % (i, 10 + i, i) for i in (1, 2, 3)).rstrip()
open(sys.argv[1], "w").write(t.substitute(bind="127.0.0.1:18080", stats_bind="127.0.0.1:18404", servers=servers,
    affinity_servers=aff, maxconn=2, deadline_s=30, server_timeout_s=35, client_timeout_s=70))
PY
	if out=$(haproxy -c -f "$T/haproxy.cfg" 2>&1); then ok "haproxy -c accepts haproxy.cfg.in"
	else nok "haproxy -c accepts haproxy.cfg.in" "$out"; fi
else
	nok "haproxy installed" "sh deploy/install-deps.sh"
fi

# 2. systemd unit
if command -v systemd-analyze >/dev/null; then
	score=$(systemd-analyze security --offline=yes deploy/umbrad.service 2>&1 | awk '/Overall exposure/ { print $(NF-2), $(NF-1) }')
	if [ -n "$score" ]; then ok "systemd-analyze security: exposure $score"
	else nok "systemd-analyze security parses deploy/umbrad.service"; fi
	# verify wants the binary at its installed path; only unit syntax errors count here.
	errs=$(systemd-analyze verify deploy/umbrad.service 2>&1 | grep -v 'is not executable\|Failed to prepare filename')
	if [ -z "$errs" ]; then ok "systemd-analyze verify (but for the binary's path)"
	else nok "systemd-analyze verify" "$errs"; fi
else
	echo "# systemd-analyze not installed: unit not checked"
fi

# 3. Runtime stage of the Dockerfile
runtime=$(awk '/^FROM .* AS runtime/ { r = 1 } r && /apt-get install/ { i = 1; next } i && /&&/ { i = 0 } i' deploy/Dockerfile |
	tr -d '\\' | tr -s ' \n' '\n' | grep -v '^$')
if [ -z "$runtime" ]; then
	nok "Dockerfile runtime stage lists packages"
elif ! apt-cache policy libc6 2>/dev/null | grep -q 'Candidate: [0-9]'; then
	echo "# no apt package lists (apt-get update): Dockerfile runtime packages not checked"
else
	missing=""
	for p in $runtime; do apt-cache show "$p" >/dev/null 2>&1 || missing="$missing $p"; done
	[ -z "$missing" ] && ok "Dockerfile runtime packages exist in Debian" || nok "Dockerfile runtime packages exist" "$missing"
	closure=$(apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
		--no-replaces --no-enhances $runtime 2>/dev/null | grep -v '^ ' | sed 's/:.*//' | sort -u)
	uncovered=""
	if [ -x "$BUILD/umbrad" ]; then
		for lib in $(ldd "$BUILD/umbrad" "$BUILD/umbra-import" 2>/dev/null | awk '/=>/ { print $3 }' | sort -u); do
			pkg=$(dpkg -S "$lib" 2>/dev/null || dpkg -S "$(readlink -f "$lib")" 2>/dev/null ||
			      dpkg -S "${lib#/usr}" 2>/dev/null)
			pkg=${pkg%%:*}
			[ -z "$pkg" ] && { uncovered="$uncovered $lib(no package)"; continue; }
			echo "$closure" | grep -qx "$pkg" || uncovered="$uncovered $pkg"
		done
		[ -z "$uncovered" ] && ok "runtime stage covers every library umbrad links" ||
			nok "runtime stage covers every library umbrad links" "$uncovered"
	else
		echo "# $BUILD/umbrad not built: library coverage not checked"
	fi
	echo "$closure" | grep -qx mesa-vulkan-drivers && ok "runtime stage has a Vulkan driver" ||
		nok "runtime stage has a Vulkan driver"
	echo "$closure" | grep -qE '^(gcc|gcc-12|build-essential|cpp|libc6-dev)$' &&
		nok "runtime stage has no compiler" || ok "runtime stage has no compiler"
fi

# 4. Version without .git: the Makefile alone in a directory outside any git work tree.
mkdir -p "$T/src" && cp Makefile "$T/src/"
v=$(cd "$T/src" && make -s print-version UMBRA_VERSION=9.9.9-test 2>/dev/null)
case "$v" in *9.9.9-test*) ok "version from UMBRA_VERSION= without .git" ;; *) nok "version from UMBRA_VERSION=" "$v" ;; esac
echo 8.8.8-file > "$T/src/VERSION"
v=$(cd "$T/src" && make -s print-version 2>/dev/null)
case "$v" in *8.8.8-file*) ok "version from a VERSION file without .git" ;; *) nok "version from VERSION" "$v" ;; esac

# 5. nginx: the shared cache's config, in a prefix of its own (runs as any user).
NGINX=$(command -v nginx 2>/dev/null || { [ -x /usr/sbin/nginx ] && echo /usr/sbin/nginx; })
if [ -n "$NGINX" ]; then
	mkdir -p "$T/nginx/cache"
	sed "s|/var/cache/nginx/umbra|$T/nginx/cache|" deploy/nginx/umbra-cache.conf >"$T/nginx/umbra-cache.conf"
	printf 'error_log %s/nginx/error.log;\npid %s/nginx/pid;\nevents {}\nhttp {\n    client_body_temp_path %s/nginx/b;\n    proxy_temp_path %s/nginx/p;\n    fastcgi_temp_path %s/nginx/f;\n    uwsgi_temp_path %s/nginx/u;\n    scgi_temp_path %s/nginx/s;\n    include %s/nginx/umbra-cache.conf;\n}\n' \
		"$T" "$T" "$T" "$T" "$T" "$T" "$T" "$T" >"$T/nginx/nginx.conf"
	if out=$("$NGINX" -t -p "$T/nginx" -c "$T/nginx/nginx.conf" -e "$T/nginx/error.log" 2>&1); then
		ok "nginx -t accepts deploy/nginx/umbra-cache.conf"
	else nok "nginx -t accepts deploy/nginx/umbra-cache.conf" "$out"; fi
else
	echo "# nginx not installed (nginx-light): deploy/nginx/umbra-cache.conf not checked"
fi

# 6. Kubernetes manifests
# Debian's python3 has python3-yaml (install-deps.sh); another python3 first on PATH may not.
PY=""
for py in python3 /usr/bin/python3; do
	"$py" -c 'import yaml' 2>/dev/null && PY=$py && break
done
if [ -z "$PY" ]; then
	nok "a python3 with the yaml module" "sh deploy/install-deps.sh (python3-yaml)"
	out=""; rc=1
else
	out=$("$PY" deploy/k8s/check.py 2>&1); rc=$?
fi
echo "$out" | grep -v '^[0-9]* passed'
p=$(echo "$out" | awk '/^[0-9]+ passed/ { print $1 }'); f=$(echo "$out" | awk '/^[0-9]+ passed/ { print $3 }')
pass=$((pass + ${p:-0})); fail=$((fail + ${f:-1}))
[ $rc -ne 0 ] && [ "${f:-1}" -eq 0 ] && fail=$((fail + 1))
if [ -n "${KUBERNETES_MODELS_DIR:-}" ] && command -v node >/dev/null; then
	out=$(node deploy/k8s/validate.mjs deploy/k8s/*.yaml 2>&1)
	echo "$out" | grep -v '^[0-9]* passed'
	p=$(echo "$out" | awk '/^[0-9]+ passed/ { print $1 }'); f=$(echo "$out" | awk '/^[0-9]+ passed/ { print $3 }')
	pass=$((pass + ${p:-0})); fail=$((fail + ${f:-1}))
else
	echo "# k8s schema validation skipped (set KUBERNETES_MODELS_DIR, see deploy/k8s/validate.mjs)"
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
