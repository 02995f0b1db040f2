/*
 * server/cli.c — umbra-render: renders one scene with the renderer library, no server.
 *
 *   umbra-render SCENE.json|- [-o OUT.png|OUT.exr] [--timings] [--device NAME]
 *
 * Exit 0 on success; 2 on an invalid scene (the problem text on stderr, as the server's
 * problem+json would say it); 1 otherwise. The extension of -o picks the format, overriding
 * output.format. Without -o the image goes to standard output.
 * UMBRA_VALIDATION=1 turns the Vulkan validation layer on; any message then fails the run.
 */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include "api.h"
#include "umbra/rnd.h"

static double now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static int usage(FILE *f, int code)
{
	fprintf(f, "usage: umbra-render SCENE.json|- [-o OUT.png|OUT.exr] [--timings] [--device NAME]\n"
	           "  Renders one scene (contract: scene-v1). Exit 0 ok, 2 invalid scene, 1 other failure.\n"
	           "  -o FILE      output file; .png or .exr picks the format (default: stdout, output.format)\n"
	           "  --timings    print per-stage milliseconds to stderr\n"
	           "  --device S   use the Vulkan device whose name contains S (also $UMBRA_DEVICE)\n");
	return code;
}

static char *read_all(const char *path, size_t *len)
{
	FILE *f = strcmp(path, "-") ? fopen(path, "rb") : stdin;
	if (!f) return NULL;
	size_t cap = 1 << 16, n = 0;
	char *buf = malloc(cap);
	while (buf) {
		size_t got = fread(buf + n, 1, cap - n, f);
		n += got;
		if (n < cap) break;
		char *nb = realloc(buf, cap *= 2);
		if (!nb) { free(buf); buf = NULL; }
		else buf = nb;
	}
	int bad = ferror(f);
	if (f != stdin) fclose(f);
	if (bad) { free(buf); return NULL; }
	*len = n;
	return buf;
}

static void log_cb(void *user, int level, const char *msg)
{
	(void)user;
	if (level <= 1) fprintf(stderr, "umbra-render: %s\n", msg);
}

int main(int argc, char **argv)
{
	const char *in = NULL, *out = NULL, *device = NULL;
	int timings = 0;
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "-o") && i + 1 < argc) out = argv[++i];
		else if (!strcmp(argv[i], "--timings")) timings = 1;
		else if (!strcmp(argv[i], "--device") && i + 1 < argc) device = argv[++i];
		else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) return usage(stdout, 0);
		else if (argv[i][0] == '-' && argv[i][1]) return usage(stderr, 1);
		else if (!in) in = argv[i];
		else return usage(stderr, 1);
	}
	if (!in) return usage(stderr, 1);

	double t0 = now_ms();
	size_t len = 0;
	char *json = read_all(in, &len);
	if (!json) {
		fprintf(stderr, "umbra-render: cannot read '%s': %s\n", in, strerror(errno));
		return 1;
	}
	struct api_limits lim;
	api_limits_defaults(&lim);
	struct api_scene *scene = NULL;
	struct api_problem prob;
	char line[1024];
	int rc = 1;
	if (api_scene_parse(json, len, &lim, &scene, &prob) != API_OK) {
		api_problem_format(&prob, line, sizeof line);
		fprintf(stderr, "umbra-render: %s\n", line);
		free(json);
		return 2;
	}
	free(json);
	if (out) {
		const char *dot = strrchr(out, '.');
		enum api_format f = scene->format;
		if (dot && !strcasecmp(dot, ".png")) f = API_FORMAT_PNG;
		else if (dot && !strcasecmp(dot, ".exr")) f = API_FORMAT_EXR;
		if (api_scene_set_format(scene, f, &prob) != API_OK) {
			api_problem_format(&prob, line, sizeof line);
			fprintf(stderr, "umbra-render: %s\n", line);
			api_scene_free(scene);
			return 2;
		}
	}
	if (api_scene_check_output(scene, &prob) != API_OK) {
		api_problem_format(&prob, line, sizeof line);
		fprintf(stderr, "umbra-render: %s\n", line);
		api_scene_free(scene);
		return 2;
	}
	double t_parse = now_ms() - t0;

	const char *v = getenv("UMBRA_VALIDATION");
	struct rnd_context_desc cd = {
		.device_name = device, .validation = v && *v == '1', .slots = 1, .log = log_cb,
	};
	struct rnd_context *ctx = NULL;
	struct rnd_error err;
	double t_ctx = now_ms();
	if (rnd_context_create(&cd, &ctx, &err) != RND_OK) {
		fprintf(stderr, "umbra-render: %s\n", err.msg);
		api_scene_free(scene);
		return 1;
	}
	t_ctx = now_ms() - t_ctx;
	struct rnd_image img;
	struct rnd_timings tm;
	enum rnd_result r = rnd_render(ctx, &scene->scene, &img, &tm, &err);
	if (r != RND_OK) {
		bool scene_fault = r == RND_ERR_INVALID || r == RND_ERR_LIMIT;
		if (scene_fault) {
			api_problem_from_render(&prob, scene, &err, r == RND_ERR_LIMIT ? 422 : 400);
			api_problem_format(&prob, line, sizeof line);
			fprintf(stderr, "umbra-render: %s\n", line);
		} else {
			fprintf(stderr, "umbra-render: render failed: %s\n", err.msg);
		}
		rc = scene_fault ? 2 : 1;
		goto out_ctx;
	}
	double t_enc = now_ms();
	uint8_t *bytes = NULL;
	size_t nbytes = 0;
	if (api_encode(scene, &img, &bytes, &nbytes, &prob) != API_OK) {
		api_problem_format(&prob, line, sizeof line);
		fprintf(stderr, "umbra-render: %s\n", line);
		goto out_img;
	}
	t_enc = now_ms() - t_enc;
	FILE *f = out ? fopen(out, "wb") : stdout;
	if (!f) {
		fprintf(stderr, "umbra-render: cannot write '%s': %s\n", out, strerror(errno));
		goto out_bytes;
	}
	size_t w = fwrite(bytes, 1, nbytes, f);
	if ((f != stdout ? fclose(f) : fflush(f)) != 0 || w != nbytes) {
		fprintf(stderr, "umbra-render: cannot write '%s': %s\n", out ? out : "(stdout)", strerror(errno));
		goto out_bytes;
	}
	if (timings)
		fprintf(stderr, "parse %.2f ms, device %.2f ms, upload %.2f ms, shadow %.2f ms, main %.2f ms, readback %.2f ms, "
		        "encode %.2f ms, total %.2f ms, %u shadow maps\n", t_parse, t_ctx, tm.upload_ms, tm.shadow_ms, tm.main_ms,
		        tm.readback_ms, t_enc, now_ms() - t0, tm.shadow_maps_rendered);
	rc = 0;
out_bytes:
	free(bytes);
out_img:
	rnd_image_release(&img);
out_ctx:
	if (rnd_context_validation_messages(ctx)) {
		fprintf(stderr, "umbra-render: %u Vulkan validation messages\n", rnd_context_validation_messages(ctx));
		rc = 1;
	}
	rnd_context_destroy(ctx);
	api_scene_free(scene);
	return rc;
}
