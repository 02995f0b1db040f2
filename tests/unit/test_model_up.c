/* tests/unit — "up": "auto" (api/model_up.h) on models built here: a plate lying flat on its
 * lowest z plane (a part on a build plate, Z-up) stands on z when it comes from an STL and
 * stays +y from a glTF file (the format's convention); the same plate turned Y-up, a tall box
 * standing on y, and a model with no flat bottom (a tetrahedron on its tip) choose y. */
#include <math.h>
#include <string.h>
#include "model.h"
#include "model_up.h"
#include "test.h"

/* An axis-aligned box of extents (sx, sy, sz) from the origin: 8 corners, 12 outward triangles. */
struct box_model {
	float pos[24];
	uint32_t idx[36];
	struct api_model_mesh mesh;
	struct api_model_instance inst;
	struct api_model m;
};

static void box_model(struct box_model *b, float sx, float sy, float sz, enum api_model_format f)
{
	static const uint32_t faces[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
	                                   2, 3, 7, 2, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
	memset(b, 0, sizeof *b);
	for (int k = 0; k < 8; k++) {   /* corner k: bit 0 x, bit 1 y (0,1,1,0 around), bit 2 z */
		b->pos[3 * k] = (k & 1) ^ ((k >> 1) & 1) ? sx : 0;
		b->pos[3 * k + 1] = (k & 2) ? sy : 0;
		b->pos[3 * k + 2] = (k & 4) ? sz : 0;
	}
	memcpy(b->idx, faces, sizeof faces);
	b->mesh = (struct api_model_mesh){.positions = b->pos, .indices = b->idx, .vertex_count = 8, .index_count = 36};
	for (int k = 0; k < 16; k++) b->inst.model[k] = k % 5 == 0;
	b->m.meshes = &b->mesh;
	b->m.mesh_count = 1;
	b->m.instances = &b->inst;
	b->m.instance_count = 1;
	b->m.format = f;
}

TEST(model_up_auto_stands_a_flat_bottomed_part_on_z)
{
	struct box_model b;
	double cy, cz;
	box_model(&b, 4, 3, 0.5, API_MODEL_STL);   /* a plate in XY: its bottom at z = 0 */
	char up = api_model_auto_up(&b.m, &cy, &cz);
	printf("    Z-up plate (STL): %c, flat y %.3f z %.3f\n", up, cy, cz);
	CHECK(up == 'z', "a plate lying on z: chose %c (y %.3f, z %.3f)", up, cy, cz);
	CHECK(fabs(cz - 12.0 / (2 * (12 + 2 + 1.5))) < 1e-6, "z contact share %.4f, want the bottom's 12 of 31 area", cz);
	b.m.format = API_MODEL_GLB;
	CHECK(api_model_auto_up(&b.m, NULL, NULL) == 'y', "glTF is +y by its specification");
	box_model(&b, 4, 0.5, 3, API_MODEL_PLY);   /* the same plate lying on y */
	CHECK(api_model_auto_up(&b.m, NULL, NULL) == 'y');
	box_model(&b, 1, 1, 1, API_MODEL_STL);   /* a cube: y and z alike, the default wins */
	CHECK(api_model_auto_up(&b.m, NULL, NULL) == 'y');
}

TEST(model_up_auto_without_a_flat_bottom_keeps_y)
{
	/* a tetrahedron on its tip in z (its flat face on top): nothing flat faces down on z */
	static const float pos[12] = {0, 0, 0, 1, 0, 1, -1, 0.5f, 1, 0, -1, 1};
	static const uint32_t idx[12] = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
	struct api_model_mesh me = {.positions = pos, .indices = idx, .vertex_count = 4, .index_count = 12};
	struct api_model_instance in = {.mesh = 0};
	for (int k = 0; k < 16; k++) in.model[k] = k % 5 == 0;
	struct api_model m = {.meshes = &me, .mesh_count = 1, .instances = &in, .instance_count = 1, .format = API_MODEL_STL};
	double cy, cz;
	char up = api_model_auto_up(&m, &cy, &cz);
	CHECK(up == 'y' && cz == 0, "tip down: chose %c (z contact %.3f)", up, cz);
}
