/* tests — server/negotiate.c (Content-Type, Accept, ETag), the server's JSON string escaper
 * (server/buf.c) and the /v1/info document (api/info.c): pure functions, no daemon. */
#include <stdio.h>
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
	CHECK(srv_accept_choice("image/avif,image/webp,*/*;q=0.8") == SRV_ACCEPT_WEBP, "a tie: WebP before AVIF");
	CHECK(srv_accept_choice("image/avif") == SRV_ACCEPT_AVIF);
	CHECK(srv_accept_choice("image/avif, image/x-exr") == SRV_ACCEPT_AVIF, "a tie: AVIF before EXR");
	CHECK(srv_accept_choice("image/avif, image/webp;q=0.9, image/png;q=0.5") == SRV_ACCEPT_AVIF);
	CHECK(srv_accept_choice("image/avif,image/webp,image/apng,image/*,*/*;q=0.8") == SRV_ACCEPT_PNG,
	      "a browser's image Accept: image/* names PNG at q 1, and a tie keeps PNG");
	CHECK(srv_accept_choice("image/avif;q=0, image/png;q=0, image/webp;q=0, image/x-exr;q=0") == SRV_ACCEPT_NONE);
	CHECK(srv_accept_choice("image/webp;q=0.5, image/x-exr;q=0.9") == SRV_ACCEPT_EXR);
	CHECK(srv_accept_choice("image/webp, image/*;q=0") == SRV_ACCEPT_WEBP);
	CHECK(srv_accept_choice("image/webp;q=0, image/png;q=0, image/x-exr;q=0") == SRV_ACCEPT_NONE);
}

TEST(negotiate_etag_of_decides_identity)
{
	uint64_t png = srv_etag_of(1, 0, "image/png", "dev", "drv");
	CHECK(png == srv_etag_of(1, 0, "image/png", "dev", "drv"), "the same inputs give the same ETag");
	CHECK(png != srv_etag_of(2, 0, "image/png", "dev", "drv"), "the scene is part of the ETag");
	CHECK(png != srv_etag_of(1, 1, "image/png", "dev", "drv"), "the asset files are part of the ETag");
	CHECK(png != srv_etag_of(1, 0, "image/x-exr", "dev", "drv"), "the format is part of the ETag");
	CHECK(png != srv_etag_of(1, 0, "image/webp", "dev", "drv") &&
	      srv_etag_of(1, 0, "image/webp", "dev", "drv") != srv_etag_of(1, 0, "image/x-exr", "dev", "drv"),
	      "WebP is a format of its own in the ETag");
	CHECK(png != srv_etag_of(1, 0, "image/png", "dev2", "drv"), "the device is part of the ETag");
	CHECK(png != srv_etag_of(1, 0, "image/png", "dev", "drv2"), "the driver is part of the ETag");
	CHECK(!strcmp(srv_format_ext("image/png"), "png") && !strcmp(srv_format_ext("image/x-exr"), "exr") &&
	      !strcmp(srv_format_ext("image/webp"), "webp"));
	uint64_t h = 0;
	char ext[8];
	CHECK(srv_result_path("/v1/renders/0123456789abcdef.png", &h, ext, sizeof ext) && h == 0x0123456789abcdefull &&
	      !strcmp(ext, "png"));
	char name[64];
	srv_result_name(name, sizeof name, 0xabcull, "image/x-exr");
	CHECK(!strcmp(name, "/v1/renders/0000000000000abc.exr"), "got %s", name);
	CHECK(srv_result_path(name, &h, ext, sizeof ext) && h == 0xabc && !strcmp(ext, "exr"), "the name reads back");
	CHECK(!srv_result_path("/v1/renders/0123456789abcdef", &h, ext, sizeof ext), "no extension");
	CHECK(!srv_result_path("/v1/renders/0123456789ABCDEF.png", &h, ext, sizeof ext), "upper-case hex");
	CHECK(!srv_result_path("/v1/renders/0123456789abcde.png", &h, ext, sizeof ext), "15 digits");
	CHECK(!srv_result_path("/v1/renders/0123456789abcdef.p/g", &h, ext, sizeof ext));
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
	                      .max_dimension = 8192, .workers = 2, .max_rss = 201326592, .rss = 150000000};
	api_limits_defaults(&in.limits);
	size_t len = 0;
	char *s = api_info_json(&in, &len);
	REQUIRE(s != NULL);
	CHECK(len == strlen(s) && len > 0 && s[len - 1] == '\n');
	CHECK(!strncmp(s, "{\"name\":\"umbrad\",\"version\":\"v\\\"1\",\"contract\":\"scene-v1\"", 52), "got %s", s);
	CHECK(strstr(s, "\"vulkan_api\":\"1.3.238\",\"cpu\":true") != NULL, "got %s", s);
	CHECK(strstr(s, "\"max_body\":67108864") != NULL && strstr(s, "\"max_dimension\":8192") != NULL);
	CHECK(strstr(s, "\"priorities\":[\"interactive\",\"bulk\"],\"rss\":150000000}") != NULL, "got %s", s);
	CHECK(strstr(s, "\"max_rss\":201326592") != NULL, "got %s", s);
	free(s);
}

/* api/scene_hash.h: the canonical scene hash behind the ETag. */
static uint64_t scene_hash_of(const char *doc, const struct api_part *parts, size_t nparts)
{
	struct api_scene *s = NULL;
	struct api_problem p;
	if (api_scene_parse_parts(doc, strlen(doc), NULL, parts, nparts, &s, &p) != API_OK) {
		fprintf(stderr, "# parse failed: %s\n", p.detail);
		return 0;
	}
	uint64_t h = s->scene_hash;
	api_scene_free(s);
	return h;
}

TEST(scene_hash_is_canonical)
{
	const char *a = "{\"width\":64,\"height\":32,\"objects\":[{\"shape\":\"sphere\",\"radius\":1}],"
	                "\"camera\":{\"position\":[0,0,5],\"target\":[0,0,0]}}";
	const char *b = "{ \"camera\" : { \"target\":[0.0,0,0], \"position\":[0, 0, 5e0] },\n"
	                "  \"objects\":[{\"radius\":1.0,\"shape\":\"sph\\u0065re\"}], \"height\":32, \"width\":64 }";
	const char *c = "{\"width\":64,\"height\":32,\"objects\":[{\"shape\":\"sphere\",\"radius\":2}],"
	                "\"camera\":{\"position\":[0,0,5],\"target\":[0,0,0]}}";
	uint64_t ha = scene_hash_of(a, NULL, 0), hb = scene_hash_of(b, NULL, 0), hc = scene_hash_of(c, NULL, 0);
	CHECK(ha != 0 && ha == hb, "key order, whitespace, escapes and number spellings: %016llx vs %016llx",
	      (unsigned long long)ha, (unsigned long long)hb);
	CHECK(hc != ha, "a changed value changes the hash");
	/* The preset's defaults are merged before hashing: naming the preset's own value changes nothing. */
	const char *t1 = "{\"preset\":\"thumbnail\",\"objects\":[{\"shape\":\"box\"}]}";
	const char *t2 = "{\"objects\":[{\"shape\":\"box\"}],\"preset\":\"thumbnail\"}";
	CHECK(scene_hash_of(t1, NULL, 0) == scene_hash_of(t2, NULL, 0) && scene_hash_of(t1, NULL, 0) != 0);
}
