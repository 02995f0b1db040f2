/* tests/util/model_compare.c — see model_compare.h. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "model_compare.h"

static bool differ(char *why, size_t n, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why, n, fmt, ap);
	va_end(ap);
	return false;
}

static bool arrays_equal(const void *a, const void *b, size_t bytes)
{
	return (!a && !b) || (a && b && !memcmp(a, b, bytes));
}

static bool mesh_equal(const struct api_model_mesh *a, const struct api_model_mesh *b, uint32_t i, float tol, char *why,
                       size_t n)
{
	if (a->vertex_count != b->vertex_count || a->index_count != b->index_count)
		return differ(why, n, "mesh %u: %u vertices %u indices against %u and %u", i, a->vertex_count, a->index_count,
		              b->vertex_count, b->index_count);
	size_t nv = a->vertex_count;
	if (a->material != b->material || a->single_sided != b->single_sided)
		return differ(why, n, "mesh %u: material %u (single-sided %d) against %u (%d)", i, a->material,
		              a->single_sided, b->material, b->single_sided);
	if (!arrays_equal(a->positions, b->positions, nv * 12)) return differ(why, n, "mesh %u: positions differ", i);
	if (!arrays_equal(a->indices, b->indices, a->index_count * 4u)) return differ(why, n, "mesh %u: indices differ", i);
	if (!arrays_equal(a->uvs, b->uvs, nv * 8)) return differ(why, n, "mesh %u: uvs differ", i);
	if (!arrays_equal(a->uvs1, b->uvs1, nv * 8)) return differ(why, n, "mesh %u: second uvs differ", i);
	if (!arrays_equal(a->colors, b->colors, nv * 4)) return differ(why, n, "mesh %u: colours differ", i);
	if (!arrays_equal(a->tangents, b->tangents, nv * 16)) return differ(why, n, "mesh %u: tangents differ", i);
	if (!a->normals || !b->normals) return differ(why, n, "mesh %u: no normals", i);
	for (size_t k = 0; k < 3 * nv; k++)
		if (!(fabsf(a->normals[k] - b->normals[k]) <= tol))
			return differ(why, n, "mesh %u: vertex %zu's normal %g against %g", i, k / 3, a->normals[k], b->normals[k]);
	if (memcmp(a->bounds, b->bounds, sizeof a->bounds) || a->closed != b->closed)
		return differ(why, n, "mesh %u: bounds or closedness differ", i);
	return true;
}

static bool texture_equal(const struct rnd_texture *a, const struct rnd_texture *b)
{
	if (!a || !b) return a == b;
	return a->width == b->width && a->height == b->height && !memcmp(a->rgba, b->rgba, (size_t)a->width * a->height * 4);
}

static bool material_equal(const struct rnd_material *a, const struct rnd_material *b)
{
	struct rnd_material x = *a, y = *b;
	for (int k = 0; k < RND_TEX_SLOTS; k++) {
		if (!texture_equal(a->textures[k], b->textures[k])) return false;
		x.textures[k] = y.textures[k] = NULL;
	}
	return !memcmp(&x, &y, sizeof x);
}

bool test_models_equal(const struct api_model *a, const struct api_model *b, float tol, char *why, size_t n)
{
	if (a->mesh_count != b->mesh_count || a->instance_count != b->instance_count ||
	    a->material_count != b->material_count || a->triangles != b->triangles)
		return differ(why, n, "%u meshes %u instances %u materials %llu triangles against %u %u %u %llu", a->mesh_count,
		              a->instance_count, a->material_count, (unsigned long long)a->triangles, b->mesh_count,
		              b->instance_count, b->material_count, (unsigned long long)b->triangles);
	for (uint32_t i = 0; i < a->mesh_count; i++)
		if (!mesh_equal(&a->meshes[i], &b->meshes[i], i, tol, why, n)) return false;
	for (uint32_t i = 0; i < a->instance_count; i++)
		if (a->instances[i].mesh != b->instances[i].mesh ||
		    memcmp(a->instances[i].model, b->instances[i].model, sizeof a->instances[i].model))
			return differ(why, n, "instance %u differs", i);
	for (uint32_t i = 0; i < a->material_count; i++)
		if (!material_equal(&a->materials[i], &b->materials[i])) return differ(why, n, "material %u differs", i);
	if ((a->warnings || b->warnings) && (!a->warnings || !b->warnings || strcmp(a->warnings, b->warnings)))
		return differ(why, n, "warnings \"%s\" against \"%s\"", a->warnings ? a->warnings : "",
		              b->warnings ? b->warnings : "");
	return true;
}
