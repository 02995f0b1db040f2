#!/bin/sh
# server/www/embed.sh SRC_DIR OUT_DIR [BENCH.json...] — the playground as one page, and that page
# as a C array (xxd -i) for server/playground.c. The page's markers are replaced in place:
# /*@css*/ by playground.css, /*@js*/ by playground.js, /*@bench*/ by
# `window.UMBRA_BENCH = {"name": scene, ...}` from the bench scenes given (none: an empty
# object). Runs at build time with no network.
set -eu
src=$1
out=$2
shift 2
page=$out/playground.html
while IFS= read -r l; do
	case "$l" in
	'/*@css*/') cat "$src/playground.css" ;;
	'/*@js*/') cat "$src/playground.js" ;;
	'/*@bench*/')
		printf 'window.UMBRA_BENCH = {'
		sep=''
		for f in "$@"; do
			printf '%s\n"%s": ' "$sep" "$(basename "$f" .json)"
			cat "$f"
			sep=','
		done
		printf '};\n' ;;
	*) printf '%s\n' "$l" ;;
	esac
done <"$src/playground.html" >"$page.tmp"
mv "$page.tmp" "$page"
(cd "$out" && xxd -i playground.html) >"$out/playground_page.h.tmp"
mv "$out/playground_page.h.tmp" "$out/playground_page.h"
