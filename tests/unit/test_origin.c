/* tests — server/origin.c: the --allowed-host and --cors-origin lists, the default Host rule by
 * the listen address, and the verdict on a request's Host, Origin and Sec-Fetch-* headers. Pure
 * functions, no daemon (tests/http/origin.sh covers the answers). */
#include <string.h>

#include "origin.h"
#include "test.h"

static enum srv_origin_verdict verdict(const struct srv_origin *o, const char *method, const char *host,
                                       const char *origin, const char *site, const char *mode)
{
	char detail[512];
	struct srv_origin_request q = { .method = method, .host = host, .origin = origin, .sec_fetch_site = site,
	                                .sec_fetch_mode = mode };
	return srv_origin_check(o, &q, detail, sizeof detail);
}

static bool init(struct srv_origin *o, const char *hosts, const char *origins, const char *listen, bool loopback,
                 char *msg, size_t size)
{
	struct srv_origin_error err;
	struct srv_origin_config c = { .allowed_hosts = hosts, .cors_origins = origins, .listen_host = listen,
	                               .loopback = loopback };
	enum srv_origin_result r = srv_origin_init(o, &c, &err);
	if (msg)
		snprintf(msg, size, "%s", err.msg);
	return r == SRV_ORIGIN_OK;
}

TEST(origin_default_hosts_by_listen_address)
{
	struct srv_origin o;
	REQUIRE(init(&o, NULL, NULL, "127.0.0.2", true, NULL, 0));
	CHECK(verdict(&o, "GET", "localhost:8080", NULL, NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "GET", "LOCALHOST.", NULL, NULL, NULL) == SRV_ORIGIN_PASS, "case and a trailing dot");
	CHECK(verdict(&o, "GET", "127.0.0.1:1", NULL, NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "GET", "[::1]:8080", NULL, NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "GET", "127.0.0.2:8080", NULL, NULL, NULL) == SRV_ORIGIN_PASS, "the listen host");
	CHECK(verdict(&o, "GET", "evil.example:8080", NULL, NULL, NULL) == SRV_ORIGIN_BAD_HOST, "DNS rebinding");
	CHECK(verdict(&o, "GET", "localhost.evil.example", NULL, NULL, NULL) == SRV_ORIGIN_BAD_HOST);
	CHECK(verdict(&o, "GET", "[::1", NULL, NULL, NULL) == SRV_ORIGIN_BAD_HOST, "malformed");
	CHECK(verdict(&o, "GET", "localhost:99999", NULL, NULL, NULL) == SRV_ORIGIN_BAD_HOST, "port out of range");
	CHECK(verdict(&o, "GET", NULL, NULL, NULL, NULL) == SRV_ORIGIN_PASS, "HTTP/1.0 without Host");
	struct srv_origin_request probe = { .method = "GET", .host = "umbra-lb", .probe = true };
	char d[256];
	CHECK(srv_origin_check(&o, &probe, d, sizeof d) == SRV_ORIGIN_PASS, "a probe is never refused by Host");
	srv_origin_release(&o);
	srv_origin_release(&o); /* twice is fine */

	REQUIRE(init(&o, NULL, NULL, "0.0.0.0", false, NULL, 0));
	CHECK(verdict(&o, "GET", "render.example.com", NULL, NULL, NULL) == SRV_ORIGIN_PASS, "non-loopback: any Host");
	srv_origin_release(&o);
}

TEST(origin_allowed_host_list)
{
	struct srv_origin o;
	char msg[256];
	REQUIRE(init(&o, " Render.Example , [::1],10.0.0.7 ", NULL, "0.0.0.0", false, msg, sizeof msg), "%s", msg);
	CHECK(verdict(&o, "GET", "render.example:8080", NULL, NULL, NULL) == SRV_ORIGIN_PASS, "port ignored");
	CHECK(verdict(&o, "GET", "[::1]", NULL, NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "GET", "10.0.0.7:80", NULL, NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "GET", "localhost", NULL, NULL, NULL) == SRV_ORIGIN_BAD_HOST, "the list replaces the default");
	char detail[512];
	struct srv_origin_request q = { .method = "GET", .host = "other.example:1" };
	CHECK(srv_origin_check(&o, &q, detail, sizeof detail) == SRV_ORIGIN_BAD_HOST);
	CHECK(strstr(detail, "--allowed-host other.example") != NULL, "%s", detail);
	srv_origin_release(&o);

	REQUIRE(init(&o, "*", NULL, "127.0.0.1", true, NULL, 0));
	CHECK(verdict(&o, "GET", "anything.example", NULL, NULL, NULL) == SRV_ORIGIN_PASS, "* on loopback");
	srv_origin_release(&o);

	CHECK(!init(&o, "render.example:8080", NULL, NULL, false, msg, sizeof msg) && strstr(msg, "port"), "%s", msg);
	CHECK(!init(&o, "a b", NULL, NULL, false, msg, sizeof msg) && strstr(msg, "--allowed-host"), "%s", msg);
	CHECK(!init(&o, " , ", NULL, NULL, false, msg, sizeof msg) && strstr(msg, "no host"), "%s", msg);
	CHECK(!init(&o, "x/y", NULL, NULL, false, msg, sizeof msg), "%s", msg);
}

TEST(origin_cors_list)
{
	struct srv_origin o;
	char msg[256];
	REQUIRE(init(&o, NULL, "https://App.example.com:443/, http://tool.example:8000", "127.0.0.1", true, msg,
	             sizeof msg), "%s", msg);
	CHECK(o.cors && !o.any_origin && o.origin_count == 2);
	CHECK(!strcmp(o.origins[0], "https://app.example.com"), "normalised: %s", o.origins[0]);
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "https://app.example.com", "cross-site", "cors") == SRV_ORIGIN_CORS);
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "http://tool.example:8000", NULL, NULL) == SRV_ORIGIN_CORS);
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "http://tool.example", NULL, NULL) == SRV_ORIGIN_REFUSED, "other port");
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "http://app.example.com", NULL, NULL) == SRV_ORIGIN_REFUSED, "other scheme");
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "null", NULL, NULL) == SRV_ORIGIN_REFUSED);
	char detail[512];
	struct srv_origin_request q = { .method = "POST", .host = "127.0.0.1:8080", .origin = "http://Evil.example" };
	CHECK(srv_origin_check(&o, &q, detail, sizeof detail) == SRV_ORIGIN_REFUSED);
	CHECK(strstr(detail, "--cors-origin http://evil.example") != NULL, "%s", detail);
	srv_origin_release(&o);

	REQUIRE(init(&o, NULL, "*", "127.0.0.1", true, NULL, 0));
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "https://any.example", "cross-site", NULL) == SRV_ORIGIN_CORS);
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "null", NULL, NULL) == SRV_ORIGIN_CORS, "* takes opaque origins");
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "not an origin", NULL, NULL) == SRV_ORIGIN_REFUSED, "never echoed");
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", NULL, "cross-site", "no-cors") == SRV_ORIGIN_PASS);
	srv_origin_release(&o);

	CHECK(!init(&o, NULL, "null", NULL, false, msg, sizeof msg) && strstr(msg, "*"), "%s", msg);
	CHECK(!init(&o, NULL, "https://app.example.com/path", NULL, false, msg, sizeof msg) &&
	      strstr(msg, "--cors-origin"), "%s", msg);
	CHECK(!init(&o, NULL, "app.example.com", NULL, false, msg, sizeof msg), "no scheme");
	CHECK(!init(&o, NULL, "https://", NULL, false, msg, sizeof msg), "no host");
	CHECK(!init(&o, NULL, "https://u@app.example.com", NULL, false, msg, sizeof msg), "user info");
}

TEST(origin_same_origin_and_sec_fetch)
{
	struct srv_origin o;
	REQUIRE(init(&o, NULL, NULL, "127.0.0.1", true, NULL, 0));
	/* The daemon's own page (the playground) posting to it. */
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "http://127.0.0.1:8080", "same-origin", "cors") == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "POST", "[::1]:8080", "http://[::1]:8080", NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "POST", "localhost", "http://localhost", NULL, NULL) == SRV_ORIGIN_PASS, "default port 80");
	CHECK(verdict(&o, "POST", "localhost", "https://localhost", NULL, NULL) == SRV_ORIGIN_PASS, "a TLS terminator");
	CHECK(verdict(&o, "POST", "localhost", "http://localhost:8080", NULL, NULL) == SRV_ORIGIN_REFUSED);
	/* Another port of the same host is another origin (same-site, not same-origin). */
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "http://127.0.0.1:8081", "same-site", "navigate") == SRV_ORIGIN_REFUSED);
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "http://localhost:8080", NULL, NULL) == SRV_ORIGIN_REFUSED);
	/* The browser's word wins over the Host comparison. */
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", "http://127.0.0.1:8080", "cross-site", "cors") == SRV_ORIGIN_REFUSED);
	/* No Origin: curl passes; a cross-site browser request does not, but a link followed does. */
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", NULL, NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", NULL, "cross-site", "no-cors") == SRV_ORIGIN_REFUSED);
	CHECK(verdict(&o, "GET", "127.0.0.1:8080", NULL, "cross-site", "no-cors") == SRV_ORIGIN_REFUSED, "an <img>");
	CHECK(verdict(&o, "GET", "127.0.0.1:8080", NULL, "cross-site", "navigate") == SRV_ORIGIN_PASS, "a link");
	CHECK(verdict(&o, "POST", "127.0.0.1:8080", NULL, "cross-site", "navigate") == SRV_ORIGIN_REFUSED);
	CHECK(verdict(&o, "GET", "127.0.0.1:8080", NULL, "same-site", "no-cors") == SRV_ORIGIN_PASS);
	CHECK(verdict(&o, "GET", "127.0.0.1:8080", NULL, "none", "navigate") == SRV_ORIGIN_PASS, "typed in");
	srv_origin_release(&o);

	/* A zeroed struct: every Host, no cross-origin caller. */
	struct srv_origin z = { 0 };
	CHECK(verdict(&z, "GET", "x.example", NULL, NULL, NULL) == SRV_ORIGIN_PASS);
	CHECK(verdict(&z, "POST", "x.example", "http://y.example", NULL, NULL) == SRV_ORIGIN_REFUSED);
	srv_origin_release(&z);
	srv_origin_release(NULL);
}
