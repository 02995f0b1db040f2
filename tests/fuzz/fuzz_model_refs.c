/*
 * tests/fuzz/fuzz_model_refs.c — libFuzzer target for api/model_refs.c, which scans untrusted
 * .gltf JSON (and a .glb's JSON chunk) and .obj / .mtl text in the daemon itself, outside the
 * importer's sandbox, and opens the files they name.
 *
 * Input: byte 0 chooses the format (gltf, glb, obj) and the source; the rest is the model.
 *   - inline: no path, no parts (every separate file must be refused or left out);
 *   - by path "models/m.*" under a root made once in a temporary directory: models/a.bin,
 *     models/t.png, models/m.mtl (whose textures include escapes), models/sub/, and a file
 *     beside the root that no reference may reach;
 *   - multipart: parts a.bin, t.png and m.mtl, where m.mtl's bytes are the input itself, so
 *     the .mtl scanner reads fuzzed text too.
 * Properties: no sanitizer report; on success every file is named, at most API_MODEL_REFS_MAX
 * of them, their bytes (each distinct file once) add up to r.bytes, and none of them is the file outside the root; on
 * failure a status of 400, 422 or 500 and a message. Any violation aborts.
 *
 *   make fuzz && build/fuzz/fuzz_model_refs -runs=1000000 tests/fuzz/corpus/fuzz_model_refs
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "model_refs.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

#define CHECK(c) do { if (!(c)) abort(); } while (0)

static char g_base[64], g_root[128];
static const char SECRET[] = "outside-the-root";

static void put(const char *rel, const char *text)
{
	char p[256];
	snprintf(p, sizeof p, "%s/%s", g_root, rel);
	FILE *f = fopen(p, "wb");
	if (!f) return;
	fputs(text, f);
	fclose(f);
}

static void cleanup(void)
{
	char cmd[128];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_base);
	if (g_base[0] && system(cmd) != 0) fprintf(stderr, "could not remove %s\n", g_base);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc;
	(void)argv;
	snprintf(g_base, sizeof g_base, "/tmp/umbra-fuzz-refs-XXXXXX");
	if (!mkdtemp(g_base)) abort();
	atexit(cleanup);
	char p[160];
	snprintf(g_root, sizeof g_root, "%s/root", g_base);
	mkdir(g_root, 0700);
	snprintf(p, sizeof p, "%s/models", g_root);
	mkdir(p, 0700);
	snprintf(p, sizeof p, "%s/models/sub", g_root);
	mkdir(p, 0700);
	snprintf(p, sizeof p, "%s/secret.bin", g_base);
	FILE *f = fopen(p, "wb");
	if (f) { fputs(SECRET, f); fclose(f); }
	put("models/a.bin", "0123456789abcdef");
	put("models/t.png", "not really a png");
	put("models/sub/s.png", "sub texture");
	put("models/m.mtl", "newmtl a\nmap_Kd t.png\nmap_Ks -s 1 1 1 sub/s.png\nbump ../../secret.bin\n"
	                    "norm /etc/hostname\nmap_d ../models/t.png\n");
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 1) return 0;
	static const enum api_model_format FMT[3] = {API_MODEL_GLTF, API_MODEL_GLB, API_MODEL_OBJ};
	static const char *const PATH[3] = {"models/m.gltf", "models/m.glb", "models/m.obj"};
	uint8_t sel = data[0];
	data++;
	size--;
	int f = sel % 3, mode = (sel / 3) % 3;
	struct api_part parts[3] = {
		{"a.bin", (const uint8_t *)"0123456789abcdef", 16},
		{"t.png", (const uint8_t *)"png", 3},
		{"m.mtl", data, size},
	};
	struct api_ref_source src = {0};
	if (mode == 1) {
		src.root = g_root;
		src.path = PATH[f];
	} else if (mode == 2) {
		src.parts = parts;
		src.nparts = 3;
	}
	struct api_model_refs r;
	int status = 0;
	char err[400] = "";
	if (api_model_refs_collect(data, size, FMT[f], &src, &r, &status, err, sizeof err) == API_OK) {
		uint64_t bytes = 0;
		CHECK(r.count <= API_MODEL_REFS_MAX);
		for (size_t i = 0; i < r.count; i++) {
			CHECK(r.files[i].name && r.files[i].name[0]);
			CHECK(r.files[i].len > 0 || mode != 1);
			bool again = false;   /* one file under several names: its bytes counted once */
			for (size_t k = 0; k < i && !again; k++)
				again = r.files[k].data == r.files[i].data && r.files[k].len == r.files[i].len;
			if (!again) bytes += r.files[i].len;
			CHECK(!(r.files[i].len == sizeof SECRET - 1 && !memcmp(r.files[i].data, SECRET, sizeof SECRET - 1)));
		}
		CHECK(bytes == r.bytes);
		CHECK(memchr(r.warning, 0, sizeof r.warning));
	} else {
		CHECK(status == 400 || status == 422 || status == 500);
		CHECK(err[0]);
	}
	api_model_refs_release(&r);
	api_model_refs_release(&r);   /* NULL-safe and idempotent after release */
	return 0;
}
