/*
 * tests/bench/edge_error.c — anti-aliasing quality for `make bench`: compares an image with a
 * reference rendered K times larger (K x K supersampled, box-filtered down here) and prints the
 * mean and largest absolute error (0..1, mean of R, G, B) over the edge pixels (where the
 * reference changes by more than 0.1 within 3 x 3 pixels: silhouettes and shadow edges) and
 * over the whole image.
 *
 *   build/tests/edge_error REFERENCE.png IMAGE.png [DIFF.png]   (8-bit PNGs; reference K times
 *   larger; DIFF.png: the absolute error x 4 as grey, to see where it is)
 */
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Reads an 8-bit PNG as RGBA into *px (caller frees). */
static int load(const char *path, unsigned char **px, unsigned *w, unsigned *h)
{
	png_image im;
	memset(&im, 0, sizeof im);
	im.version = PNG_IMAGE_VERSION;
	if (!png_image_begin_read_from_file(&im, path)) { fprintf(stderr, "edge_error: %s: %s\n", path, im.message); return -1; }
	im.format = PNG_FORMAT_RGBA;
	*px = malloc(PNG_IMAGE_SIZE(im));
	if (!*px || !png_image_finish_read(&im, NULL, *px, 0, NULL)) {
		fprintf(stderr, "edge_error: %s: %s\n", path, im.message);
		free(*px);
		png_image_free(&im);
		return -1;
	}
	*w = im.width;
	*h = im.height;
	return 0;
}

int main(int argc, char **argv)
{
	if (argc != 3 && argc != 4) { fprintf(stderr, "usage: edge_error REFERENCE.png IMAGE.png [DIFF.png]\n"); return 2; }
	unsigned char *ref, *img;
	unsigned rw, rh, w, h;
	if (load(argv[1], &ref, &rw, &rh)) return 1;
	if (load(argv[2], &img, &w, &h)) { free(ref); return 1; }
	unsigned k = w ? rw / w : 0;
	if (!k || rw != k * w || rh != k * h) {
		fprintf(stderr, "edge_error: reference %ux%u is not a multiple of %ux%u\n", rw, rh, w, h);
		free(ref); free(img);
		return 1;
	}
	/* Box filter: the mean of R, G, B over each K x K block, in 0..1. */
	float *down = calloc((size_t)w * h, sizeof *down), *test = calloc((size_t)w * h, sizeof *test);
	if (!down || !test) { free(ref); free(img); free(down); free(test); return 1; }
	for (unsigned y = 0; y < rh; y++)
		for (unsigned x = 0; x < rw; x++) {
			const unsigned char *p = ref + 4 * ((size_t)y * rw + x);
			down[(y / k) * w + x / k] += (p[0] + p[1] + p[2]) / (3.0f * 255.0f * k * k);
		}
	for (size_t i = 0; i < (size_t)w * h; i++) test[i] = (img[4 * i] + img[4 * i + 1] + img[4 * i + 2]) / (3.0f * 255.0f);
	double edge_sum = 0, all_sum = 0, edge_max = 0;
	size_t edges = 0;
	for (unsigned y = 0; y < h; y++)
		for (unsigned x = 0; x < w; x++) {
			float lo = 1e9f, hi = -1e9f;
			for (int dy = -1; dy <= 1; dy++)
				for (int dx = -1; dx <= 1; dx++) {
					int xx = (int)x + dx, yy = (int)y + dy;
					if (xx < 0 || yy < 0 || xx >= (int)w || yy >= (int)h) continue;
					float v = down[(size_t)yy * w + (size_t)xx];
					lo = v < lo ? v : lo;
					hi = v > hi ? v : hi;
				}
			double e = fabs((double)test[(size_t)y * w + x] - down[(size_t)y * w + x]);
			all_sum += e;
			if (hi - lo > 0.1f) { edge_sum += e; edges++; if (e > edge_max) edge_max = e; }
		}
	if (argc == 4) {
		png_image out;
		memset(&out, 0, sizeof out);
		out.version = PNG_IMAGE_VERSION;
		out.width = w;
		out.height = h;
		out.format = PNG_FORMAT_GRAY;
		for (size_t i = 0; i < (size_t)w * h; i++) {
			float e = 4.0f * fabsf(test[i] - down[i]) * 255.0f;
			img[i] = (unsigned char)(e > 255.0f ? 255.0f : e);
		}
		if (!png_image_write_to_file(&out, argv[3], 0, img, 0, NULL)) fprintf(stderr, "edge_error: %s\n", out.message);
	}
	printf("%s: %zu edge pixels, edge mean abs error %.4f, edge max %.4f, whole-image mean %.4f\n", argv[2], edges,
	       edges ? edge_sum / (double)edges : 0.0, edge_max, all_sum / ((double)w * h));
	free(ref); free(img); free(down); free(test);
	return 0;
}
