/*
 * api/model_strokes — a mesh's points and lines as geometry the renderer draws (see
 * model_conv.h): a line segment becomes a thin triangular prism (three flat sides, six
 * triangles) of radius `r` along it, a point a small octahedron (eight triangles) of radius
 * 2.5 r around it. Both are in the model's space, so they shade, cast shadows and take levels
 * like any triangle; their width on screen follows the model's size in the image (convert()
 * takes r as 1/500 of the model's box diagonal: about a pixel's width of line and a
 * 2.5-pixel dot in a 512-pixel thumbnail), not a fixed pixel width as a viewer's GL_LINES.
 */
#include <math.h>
#include <string.h>
#include "errmsg.h"
#include "model_conv.h"

#define PRISM_VERTS 12   /* three sides, four corners each (flat normals) */
#define OCTA_VERTS 24    /* eight faces, three corners each (flat normals) */

static void sub(const float a[3], const float b[3], float o[3]) { for (int k = 0; k < 3; k++) o[k] = a[k] - b[k]; }
static void cross3(const float a[3], const float b[3], float o[3])
{
	o[0] = a[1] * b[2] - a[2] * b[1];
	o[1] = a[2] * b[0] - a[0] * b[2];
	o[2] = a[0] * b[1] - a[1] * b[0];
}
static bool unit(float v[3])
{
	float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
	if (!(l > 1e-20f)) return false;
	for (int k = 0; k < 3; k++) v[k] /= l;
	return true;
}

/* One quad (corners p0..p3 in order, outward normal n) at vertex v0, index i0. */
static void quad(float *pos, float *nrm, uint32_t *idx, uint32_t v0, const float *p[4], const float n[3])
{
	for (int k = 0; k < 4; k++) {
		memcpy(pos + 3 * (size_t)(v0 + (uint32_t)k), p[k], 12);
		memcpy(nrm + 3 * (size_t)(v0 + (uint32_t)k), n, 12);
	}
	const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
	for (int k = 0; k < 6; k++) idx[k] = v0 + q[k];
}

/* The prism around segment a-b: 12 vertices at v0, 18 indices. */
static void prism(const float a[3], const float b[3], float r, float *pos, float *nrm, uint32_t *idx, uint32_t v0)
{
	float d[3], u[3], w[3], e[3][3], ea[3][3], eb[3][3];
	sub(b, a, d);
	if (!unit(d)) d[0] = 1, d[1] = d[2] = 0;
	float t[3] = {fabsf(d[1]) < 0.9f ? 0.0f : 1.0f, fabsf(d[1]) < 0.9f ? 1.0f : 0.0f, 0};
	cross3(d, t, u);
	unit(u);
	cross3(d, u, w);
	for (int s = 0; s < 3; s++) {   /* the three edges of the prism, 120 degrees apart */
		float an = 2.0943951f * (float)s, cs = cosf(an), sn = sinf(an);
		for (int k = 0; k < 3; k++) {
			e[s][k] = r * (cs * u[k] + sn * w[k]);
			ea[s][k] = a[k] + e[s][k];
			eb[s][k] = b[k] + e[s][k];
		}
	}
	for (int s = 0; s < 3; s++) {
		int s1 = (s + 1) % 3;
		float n[3] = {e[s][0] + e[s1][0], e[s][1] + e[s1][1], e[s][2] + e[s1][2]};
		unit(n);
		const float *p[4] = {ea[s], ea[s1], eb[s1], eb[s]};
		quad(pos, nrm, idx + 6 * s, v0 + 4 * (uint32_t)s, p, n);
		/* wound so that n faces out: flip when the corners turn the other way */
		float x[3], y[3], c[3];
		sub(ea[s1], ea[s], x);
		sub(eb[s], ea[s], y);
		cross3(x, y, c);
		if (c[0] * n[0] + c[1] * n[1] + c[2] * n[2] < 0)
			for (int k = 0; k < 6; k += 3) {
				uint32_t tmp = idx[6 * s + k + 1];
				idx[6 * s + k + 1] = idx[6 * s + k + 2];
				idx[6 * s + k + 2] = tmp;
			}
	}
}

/* The octahedron of radius r around p: 24 vertices at v0, 24 indices, outward. */
static void octahedron(const float p[3], float r, float *pos, float *nrm, uint32_t *idx, uint32_t v0)
{
	for (int f = 0; f < 8; f++) {
		float sx = f & 1 ? -1.0f : 1.0f, sy = f & 2 ? -1.0f : 1.0f, sz = f & 4 ? -1.0f : 1.0f;
		float c[3][3] = {{p[0] + sx * r, p[1], p[2]}, {p[0], p[1] + sy * r, p[2]}, {p[0], p[1], p[2] + sz * r}};
		float n[3] = {sx, sy, sz};
		unit(n);
		bool flip = sx * sy * sz < 0;   /* x, y, z corners turn the other way in odd octants */
		for (int k = 0; k < 3; k++) {
			uint32_t v = v0 + 3 * (uint32_t)f + (uint32_t)k;
			memcpy(pos + 3 * (size_t)v, c[k], 12);
			memcpy(nrm + 3 * (size_t)v, n, 12);
			idx[3 * f + k] = v0 + 3 * (uint32_t)f + (uint32_t)(flip && k ? 3 - k : k);
		}
	}
}

int api_conv_strokes(struct api_conv *c, const struct aiMesh *am, float r, struct api_model_mesh *out)
{
	uint64_t nv = 0, ni = 0;
	for (unsigned f = 0; f < am->mNumFaces; f++) {
		unsigned n = am->mFaces[f].mNumIndices;
		if (n == 2) nv += PRISM_VERTS, ni += 18;
		if (n == 1) nv += OCTA_VERTS, ni += 24;
	}
	memset(out, 0, sizeof *out);
	if (!nv) return 0;
	if (nv > UINT32_MAX / 4 || ni > UINT32_MAX / 4)
		return api_err_set(c->err, c->errsize, "mesh \"%.64s\": too many points and lines", am->mName.data), -1;
	float *pos = api_conv_alloc(c, (size_t)nv, 12), *nrm = api_conv_alloc(c, (size_t)nv, 12);
	uint32_t *idx = api_conv_alloc(c, (size_t)ni, 4);
	if (!pos || !nrm || !idx) return api_err_set(c->err, c->errsize, "out of memory importing the model"), -1;
	uint32_t v = 0, i = 0;
	for (unsigned f = 0; f < am->mNumFaces; f++) {
		const struct aiFace *face = &am->mFaces[f];
		if (face->mNumIndices != 1 && face->mNumIndices != 2) continue;
		float p[2][3];
		for (unsigned k = 0; k < face->mNumIndices; k++) {
			if (face->mIndices[k] >= am->mNumVertices)
				return api_err_set(c->err, c->errsize, "mesh \"%.64s\": face %u refers to vertex %u of %u", am->mName.data,
				                   f, face->mIndices[k], am->mNumVertices), -1;
			const struct aiVector3D *q = &am->mVertices[face->mIndices[k]];
			if (!isfinite(q->x) || !isfinite(q->y) || !isfinite(q->z))
				return api_err_set(c->err, c->errsize, "mesh \"%.64s\": a point that is not finite", am->mName.data), -1;
			p[k][0] = q->x, p[k][1] = q->y, p[k][2] = q->z;
		}
		if (face->mNumIndices == 2) {
			prism(p[0], p[1], r, pos, nrm, idx + i, v);
			v += PRISM_VERTS, i += 18;
		} else {
			octahedron(p[0], 2.5f * r, pos, nrm, idx + i, v);
			v += OCTA_VERTS, i += 24;
		}
	}
	out->positions = pos;
	out->normals = nrm;
	out->indices = idx;
	out->vertex_count = v;
	out->index_count = i;
	out->material = am->mMaterialIndex;
	out->single_sided = false;
	return 0;
}
