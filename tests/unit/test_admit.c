/* tests/unit — admission by memory (server/admit.c) as a parse grows what it holds (issue 29:
 * parse-time memory counted), and the image header read that sizes a decode before it runs
 * (api/image_decode.c api_image_header_size). */
#include <string.h>
#include <time.h>
#include "admit.h"
#include "model.h"
#include "test.h"

static double mono_s(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec + t.tv_nsec / 1e9;
}

TEST(admit_grow_keeps_what_a_request_holds)
{
	struct srv_admit a;
	struct api_problem p;
	srv_admit_init(&a, 100);
	CHECK(srv_admit_grow(&a, NULL, 0, 60, 0, &p) == 0, "A takes 60 of 100");
	CHECK(srv_admit_grow(&a, NULL, 0, 30, 0, &p) == 0, "B takes 30 more");
	memset(&p, 0, sizeof p);
	CHECK(srv_admit_grow(&a, NULL, 60, 50, 0, &p) != 0 && p.status == 422 && strstr(p.detail, "--max-memory"),
	      "A's 60 + 50 more is over the budget alone: 422 (%d %s)", p.status, p.detail);
	/* B, holding 30, wants 20 more while A holds 60: it waits (what it holds given back
	 * meanwhile) and, A releasing nothing, passes its deadline still holding its 30. */
	memset(&p, 0, sizeof p);
	CHECK(srv_admit_grow(&a, NULL, 30, 20, mono_s() + 0.05, &p) != 0 && p.status == 504, "B waits, then 504 (%d)",
	      p.status);
	srv_admit_release(&a, 60);   /* A answered */
	CHECK(srv_admit_grow(&a, NULL, 30, 20, mono_s() + 5, &p) == 0, "with A gone, B holds 50");
	srv_admit_release(&a, 50);
	CHECK(srv_admit_grow(&a, NULL, 0, 100, 0, &p) == 0, "everything is back: 100 admitted alone");
	srv_admit_release(&a, 100);
	srv_admit_destroy(&a);
}

TEST(image_header_size_png_and_jpeg)
{
	uint32_t w = 0, h = 0;
	static const uint8_t png[24] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
	                                0, 0, 0x20, 0, 0, 0, 0x10, 0};
	CHECK(api_image_header_size(png, sizeof png, &w, &h) && w == 8192 && h == 4096, "PNG IHDR: %ux%u", w, h);
	/* SOI, an APP0 of 16 bytes, a DHT (not a frame), then SOF2 (progressive) 300 high, 500 wide */
	static const uint8_t jpg[] = {0xff, 0xd8, 0xff, 0xe0, 0, 16, 'J', 'F', 'I', 'F', 0, 1, 1, 0, 0, 1, 0, 1, 0, 0,
	                              0xff, 0xc4, 0, 3, 0, 0xff, 0xc2, 0, 11, 8, 0x01, 0x2c, 0x01, 0xf4, 1, 1, 0x11, 0};
	w = h = 0;
	CHECK(api_image_header_size(jpg, sizeof jpg, &w, &h) && w == 500 && h == 300, "JPEG SOF2: %ux%u", w, h);
	CHECK(!api_image_header_size(jpg, 12, &w, &h), "a JPEG cut before its frame says nothing");
	static const uint8_t junk[] = "GIF89a........................";
	CHECK(!api_image_header_size(junk, sizeof junk, &w, &h), "not a PNG or JPEG");
}
