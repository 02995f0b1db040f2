#!/bin/sh
# server/www/embed.sh SRC_DIR OUT_DIR SCHEMA [BENCH.json...] — the playground as one page, that page as
# a C array (xxd -i) for server/playground.c, and the page's Content-Security-Policy. The page's
# marker lines are replaced in place: <style>/*@css*/</style> by playground.css, and each
# <script>/*@NAME*/</script> by NAME.js: SRC_DIR's (the page's scripts, by job, in the page's
# order: they share its globals), or the two made here: bench.js, `window.UMBRA_BENCH = {"name":
# scene, ...}` from the bench scenes given (none: an empty object), and schema.js,
# `window.UMBRA_SCHEMA = ` SCHEMA (api/scene.schema.json: the editor's completion and help). Each
# inline block is exactly its file between the tags, so the policy allows it by the SHA-256 of
# that file ('sha256-...'): no 'unsafe-inline'. Runs at build time with no network.
set -eu
src=$1
out=$2
schema=$3
shift 3
page=$out/playground.html
bench() {
	printf 'window.UMBRA_BENCH = {'
	sep=''
	for f in "$@"; do
		printf '%s\n"%s": ' "$sep" "$(basename "$f" .json)"
		cat "$f"
		sep=','
	done
	printf '};\n'
}
bench "$@" >"$out/bench.js"
{ printf 'window.UMBRA_SCHEMA = '; cat "$schema"; printf ';\n'; } >"$out/schema.js"
# 'sha256-BASE64' of a file's bytes.
hash() { printf "'sha256-%s'" "$(sha256sum <"$1" | cut -d' ' -f1 | xxd -r -p | base64 -w0)"; }
# The file of a script marker's NAME (made here, or SRC_DIR's).
script_file() { case "$1" in bench | schema) echo "$out/$1.js" ;; *) echo "$src/$1.js" ;; esac; }
scripts=""
while IFS= read -r l; do
	case "$l" in
	'<style>/*@css*/</style>') printf '<style>'; cat "$src/playground.css"; printf '</style>\n' ;;
	'<script>/*@'*'*/</script>')
		name=${l#'<script>/*@'}; name=${name%'*/</script>'}
		f=$(script_file "$name")
		[ -f "$f" ] || { echo "embed.sh: no $f for the marker $l" >&2; exit 1; }
		printf '<script>'; cat "$f"; printf '</script>\n'
		scripts="$scripts $(hash "$f")" ;;
	*) printf '%s\n' "$l" ;;
	esac
done <"$src/playground.html" >"$page.tmp"
mv "$page.tmp" "$page"
# Images are the renders' blob: URLs; fetches go to this daemon only; nothing may frame the page, and no form or <base> may point elsewhere.
csp="default-src 'self'; script-src${scripts}; style-src $(hash "$src/playground.css"); img-src 'self' blob:; connect-src 'self'; object-src 'none'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'"
{
	(cd "$out" && xxd -i playground.html)
	printf 'static const char playground_csp[] = "%s";\n' "$csp"
} >"$out/playground_page.h.tmp"
mv "$out/playground_page.h.tmp" "$out/playground_page.h"
