/*
 * tests/fuzz/image_seeds.c — writes the small PNG and JPEG seeds of tests/fuzz/fuzz_image.c,
 * one per decoder path worth reaching (PNG: grey, grey+alpha interlaced, palette with tRNS,
 * 16-bit RGB, 1-bit grey, RGBA; JPEG: baseline RGB 4:2:0 with restarts, greyscale, progressive,
 * CMYK). Not part of the build; the output is committed:
 *
 *   cc -o /tmp/image_seeds tests/fuzz/image_seeds.c $(pkg-config --cflags --libs libpng) -ljpeg
 *   /tmp/image_seeds tests/fuzz/corpus/fuzz_image
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <png.h>
#include <jpeglib.h>

static char dir[512];

static FILE *open_out(const char *name)
{
	char path[600];
	snprintf(path, sizeof path, "%s/%s", dir, name);
	FILE *f = fopen(path, "wb");
	if (!f) { perror(path); exit(1); }
	return f;
}

/* A PNG of w x h; bit depth, colour type and interlace as given; pixel bytes made up. */
static void png(const char *name, int w, int h, int depth, int ctype, int interlace)
{
	FILE *f = open_out(name);
	png_structp p = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
	png_infop info = png_create_info_struct(p);
	if (setjmp(png_jmpbuf(p))) { fprintf(stderr, "%s: libpng error\n", name); exit(1); }
	png_init_io(p, f);
	png_set_IHDR(p, info, (png_uint_32)w, (png_uint_32)h, depth, ctype, interlace, PNG_COMPRESSION_TYPE_DEFAULT,
	             PNG_FILTER_TYPE_DEFAULT);
	if (ctype == PNG_COLOR_TYPE_PALETTE) {
		png_color pal[4] = { { 255, 0, 0 }, { 0, 255, 0 }, { 0, 0, 255 }, { 9, 9, 9 } };
		png_byte trns[2] = { 0, 128 };
		png_set_PLTE(p, info, pal, 4);
		png_set_tRNS(p, info, trns, 2, NULL);
	}
	png_write_info(p, info);
	int passes = png_set_interlace_handling(p);
	size_t rowbytes = png_get_rowbytes(p, info);
	png_bytep row = malloc(rowbytes);
	for (int pass = 0; pass < passes; pass++)
		for (int y = 0; y < h; y++) {
			for (size_t i = 0; i < rowbytes; i++) row[i] = (png_byte)(i * 37 + (size_t)y * 11);
			if (ctype == PNG_COLOR_TYPE_PALETTE)
				for (size_t i = 0; i < rowbytes; i++) row[i] &= depth == 8 ? 3 : 0x55;
			png_write_row(p, row);
		}
	png_write_end(p, NULL);
	png_destroy_write_struct(&p, &info);
	free(row);
	fclose(f);
}

static void jpeg(const char *name, int w, int h, J_COLOR_SPACE cs, int comps, int progressive, int restart)
{
	FILE *f = open_out(name);
	struct jpeg_compress_struct c;
	struct jpeg_error_mgr jerr;
	c.err = jpeg_std_error(&jerr);
	jpeg_create_compress(&c);
	jpeg_stdio_dest(&c, f);
	c.image_width = (JDIMENSION)w;
	c.image_height = (JDIMENSION)h;
	c.input_components = comps;
	c.in_color_space = cs;
	jpeg_set_defaults(&c);
	jpeg_set_quality(&c, 50, TRUE);
	if (progressive) jpeg_simple_progression(&c);
	c.restart_in_rows = restart;
	jpeg_start_compress(&c, TRUE);
	JSAMPLE *row = malloc((size_t)w * (size_t)comps);
	while (c.next_scanline < c.image_height) {
		for (int i = 0; i < w * comps; i++) row[i] = (JSAMPLE)(i * 29 + (int)c.next_scanline * 7);
		JSAMPROW rows[1] = { row };
		jpeg_write_scanlines(&c, rows, 1);
	}
	jpeg_finish_compress(&c);
	jpeg_destroy_compress(&c);
	free(row);
	fclose(f);
}

int main(int argc, char **argv)
{
	if (argc != 2) { fprintf(stderr, "usage: %s DIR\n", argv[0]); return 2; }
	snprintf(dir, sizeof dir, "%s", argv[1]);
	png("rgba8.png", 4, 3, 8, PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE);
	png("grey8.png", 5, 5, 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE);
	png("grey_alpha_adam7.png", 9, 9, 8, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_ADAM7);
	png("palette_trns.png", 4, 4, 8, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE);
	png("palette2.png", 7, 3, 2, PNG_COLOR_TYPE_PALETTE, PNG_INTERLACE_NONE);
	png("rgb16.png", 3, 3, 16, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE);
	png("grey1.png", 8, 2, 1, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE);
	jpeg("rgb_420_restart.jpg", 17, 13, JCS_RGB, 3, 0, 1);
	jpeg("grey.jpg", 16, 8, JCS_GRAYSCALE, 1, 0, 0);
	jpeg("progressive.jpg", 16, 16, JCS_RGB, 3, 1, 0);
	jpeg("cmyk.jpg", 8, 8, JCS_CMYK, 4, 0, 0);
	return 0;
}
