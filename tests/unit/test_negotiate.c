/* tests — server/negotiate.c (Content-Type, Accept, ETag), the server's JSON string escaper
 * (server/buf.c) and the /v1/info document (api/info.c): pure functions, no daemon. */
#include <stdlib.h>
#include <string.h>

#include "api.h"
#include "buf.h"
#include "negotiate.h"
#include "test.h"

TEST(negotiate_content_types)
{
	CHECK(srv_json_content_type("application/json"));
	CHECK(srv_json_content_type("  application/json; charset=utf-8"));
	CHECK(srv_json_content_type("APPLICATION/JSON"));
	CHECK(srv_json_content_type("application/scene+json"));
	CHECK(!srv_json_content_type("application/+json"), "a bare +json suffix names no type");
	CHECK(!srv_json_content_type("text/json"));
	CHECK(!srv_json_content_type("application/jsonx"));
	CHECK(!srv_json_content_type(NULL));
	CHECK(srv_multipart_content_type("multipart/form-data; boundary=x"));
	CHECK(srv_multipart_content_type("multipart/form-data"), "the boundary check is libmicrohttpd's");
	CHECK(!srv_multipart_content_type("multipart/form-datax"));
	CHECK(!srv_multipart_content_type("multipart/mixed; boundary=x"));
	CHECK(!srv_multipart_content_type(NULL));
}

TEST(negotiate_accept)
{
	CHECK(srv_accept_choice(NULL) == SRV_ACCEPT_PNG);
	CHECK(srv_accept_choice("") == SRV_ACCEPT_PNG);
	CHECK(srv_accept_choice("image/x-exr") == SRV_ACCEPT_EXR);
	CHECK(srv_accept_choice("image/png, image/x-exr") == SRV_ACCEPT_PNG, "a tie keeps the default");
	CHECK(srv_accept_choice("image/png;q=0.5, image/x-exr;q=0.9") == SRV_ACCEPT_EXR);
	CHECK(srv_accept_choice("image/x-exr;q=0.4, image/*;q=0.8") == SRV_ACCEPT_PNG, "the wildcard counts for PNG");
	CHECK(srv_accept_choice("*/*") == SRV_ACCEPT_PNG);
	CHECK(srv_accept_choice("text/html") == SRV_ACCEPT_NONE);
	CHECK(srv_accept_choice("image/png;q=0, image/x-exr;q=0") == SRV_ACCEPT_NONE);
	CHECK(srv_accept_choice("IMAGE/X-EXR ") == SRV_ACCEPT_EXR);
	CHECK(srv_accept_choice("image/webp") == SRV_ACCEPT_WEBP);
	CHECK(srv_accept_choice("image/webp, image/png") == SRV_ACCEPT_PNG, "a tie keeps the default");
	CHECK(srv_accept_choice("image/webp, image/x-exr") == SRV_ACCEPT_WEBP, "a tie: WebP before EXR");
	CHECK(srv_accept_choice("image/avif,image/webp,*/*;q=0.8") == SRV_ACCEPT_WEBP, "a browser's image Accept");
	CHECK(srv_accept_choice("image/webp;q=0.5, image/x-exr;q=0.9") == SRV_ACCEPT_EXR);
	CHECK(srv_accept_choice("image/webp, image/*;q=0") == SRV_ACCEPT_WEBP);
	CHECK(srv_accept_choice("image/webp;q=0, image/png;q=0, image/x-exr;q=0") == SRV_ACCEPT_NONE);
}

TEST(negotiate_etag_streams_and_formats)
{
	const char body[] = "{\"width\":64,\"height\":64,\"objects\":[]}";
	size_t n = strlen(body);
	uint64_t whole = srv_etag_body(srv_etag_start(), body, n);
	/* However the body is cut into chunks, the hash is the same. */
	for (size_t cut = 0; cut <= n; cut += 5) {
		uint64_t h = srv_etag_body(srv_etag_start(), body, cut);
		h = srv_etag_body(h, body + cut, n - cut);
		CHECK(h == whole, "cut at %zu", cut);
	}
	uint64_t png = srv_etag_finish(whole, SRV_ACCEPT_PNG, "dev", "drv");
	uint64_t exr = srv_etag_finish(whole, SRV_ACCEPT_EXR, "dev", "drv");
	uint64_t webp = srv_etag_finish(whole, SRV_ACCEPT_WEBP, "dev", "drv");
	CHECK(png != exr && webp != png && webp != exr, "the format is part of the ETag");
	CHECK(srv_etag_finish(whole, SRV_ACCEPT_PNG, "dev2", "drv") != png, "the device is part of the ETag");
	CHECK(srv_etag_assets(png, 1) != png && srv_etag_assets(png, 1) != srv_etag_assets(png, 2));
	char etag[40];
	srv_etag_format(etag, sizeof etag, 0x0123456789abcdefull);
	CHECK(!strcmp(etag, "\"0123456789abcdef\""), "got %s", etag);
	CHECK(srv_etag_matches("\"0123456789abcdef\"", etag));
	CHECK(srv_etag_matches("\"x\", W/\"0123456789abcdef\"", etag), "weak comparison of a listed tag");
	CHECK(!srv_etag_matches("*", etag), "* never matches");
	CHECK(!srv_etag_matches("\"0123456789abcde\"", etag));
	CHECK(!srv_etag_matches(NULL, etag));
}

TEST(json_escape_bounds)
{
	char out[64];
	srv_json_escape(out, sizeof out, "a\"b\\c\n\x7f");
	CHECK(!strcmp(out, "a\\\"b\\\\c\\u000a\\u007f"), "got %s", out);
	char small[8];
	srv_json_escape(small, sizeof small, "\n\n\n");
	CHECK(!strcmp(small, "\\u000a"), "an escape that does not fit is left out whole, got %s", small);
	srv_json_escape(small, sizeof small, "abcdefghij");
	CHECK(strlen(small) < sizeof small);
}

TEST(info_document_is_json)
{
	struct api_info in = {.version = "v\"1", .device = "lavapipe", .driver = "llvmpipe", .driver_info = "x",
	                      .vulkan_api = (1u << 22) | (3u << 12) | 238u, .cpu = true, .max_body = 67108864,
	                      .max_dimension = 8192, .workers = 2};
	api_limits_defaults(&in.limits);
	size_t len = 0;
	char *s = api_info_json(&in, &len);
	REQUIRE(s != NULL);
	CHECK(len == strlen(s) && len > 0 && s[len - 1] == '\n');
	CHECK(!strncmp(s, "{\"name\":\"umbrad\",\"version\":\"v\\\"1\",\"contract\":\"scene-v1\"", 52), "got %s", s);
	CHECK(strstr(s, "\"vulkan_api\":\"1.3.238\",\"cpu\":true") != NULL, "got %s", s);
	CHECK(strstr(s, "\"max_body\":67108864") != NULL && strstr(s, "\"max_dimension\":8192") != NULL);
	CHECK(strstr(s, "\"priorities\":[\"interactive\",\"bulk\"]}") != NULL, "got %s", s);
	free(s);
}
