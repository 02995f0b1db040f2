/*
 * server/playground — the playground page (server/www/), embedded at build time as a C array
 * ($(BUILD)/www/playground_page.h, made by server/www/embed.sh with xxd -i): GET / and
 * GET /playground answer it unless --no-playground / UMBRA_NO_PLAYGROUND=1.
 * The page is static and fetches nothing but this daemon's /v1/render and /v1/info; its
 * Content-Security-Policy (srv_playground_csp, sent by http.c) is built with it and allows only
 * its own inline blocks, by hash.
 * Thread-safe: the page is read-only.
 */
#include <stdlib.h>
#include <string.h>
#include "srv.h"
#include "playground_page.h"

bool srv_playground_path(const char *url)
{
	return !strcmp(url, "/") || !strcmp(url, "/playground");
}

char *srv_playground_page(size_t *len)
{
	/* A copy: the daemon's answers own their body (libmicrohttpd frees it). */
	char *b = malloc(playground_html_len);
	if (!b) return NULL;
	memcpy(b, playground_html, playground_html_len);
	*len = playground_html_len;
	return b;
}

const char *srv_playground_csp(void)
{
	return playground_csp;
}
