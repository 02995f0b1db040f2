/*
 * api/draco — libdraco's mesh decoder behind a C interface (see the header).
 */
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>
#include "draco.h"

struct api_draco {
	std::unique_ptr<draco::Mesh> mesh;
};

static void say(char *err, size_t errsize, const char *what)
{
	if (err && errsize) std::snprintf(err, errsize, "%s", what);
}

enum api_draco_result api_draco_decode(const uint8_t *src, size_t n, struct api_draco **out, char *err,
                                       size_t errsize)
{
	*out = nullptr;
	try {
		draco::DecoderBuffer buf;
		buf.Init(reinterpret_cast<const char *>(src), n);
		draco::Decoder dec;
		auto r = dec.DecodeMeshFromBuffer(&buf);
		if (!r.ok()) {
			say(err, errsize, r.status().error_msg());
			return API_DRACO_BAD;
		}
		*out = new api_draco{std::move(r).value()};
		return API_DRACO_OK;
	} catch (const std::bad_alloc &) {
		say(err, errsize, "out of memory");
		return API_DRACO_NO_MEMORY;
	} catch (...) {
		say(err, errsize, "the decoder failed");
		return API_DRACO_BAD;
	}
}

void api_draco_free(struct api_draco *d)
{
	delete d;
}

uint32_t api_draco_points(const struct api_draco *d)
{
	return d->mesh->num_points();
}

uint32_t api_draco_faces(const struct api_draco *d)
{
	return d->mesh->num_faces();
}

void api_draco_indices(const struct api_draco *d, uint32_t *out)
{
	const draco::Mesh &m = *d->mesh;
	for (draco::FaceIndex f(0); f < m.num_faces(); ++f)
		for (int k = 0; k < 3; k++) *out++ = m.face(f)[k].value();
}

int api_draco_components(const struct api_draco *d, uint32_t uid)
{
	const draco::PointAttribute *a = d->mesh->GetAttributeByUniqueId(uid);
	return a ? a->num_components() : 0;
}

template <typename T>
static bool convert(const draco::Mesh &m, const draco::PointAttribute &a, int comps, void *out)
{
	T *o = static_cast<T *>(out);
	for (draco::PointIndex i(0); i < m.num_points(); ++i, o += comps)
		if (!a.ConvertValue<T>(a.mapped_index(i), static_cast<int8_t>(comps), o)) return false;
	return true;
}

enum api_draco_result api_draco_attribute(const struct api_draco *d, uint32_t uid, int ct, int comps, void *out,
                                          char *err, size_t errsize)
{
	const draco::Mesh &m = *d->mesh;
	const draco::PointAttribute *a = m.GetAttributeByUniqueId(uid);
	if (!a || a->num_components() != comps) {
		say(err, errsize, a ? "its component count differs from the accessor's type" : "no attribute of that id");
		return API_DRACO_BAD;
	}
	bool ok = false;
	switch (ct) {
	case 5120: ok = convert<int8_t>(m, *a, comps, out); break;
	case 5121: ok = convert<uint8_t>(m, *a, comps, out); break;
	case 5122: ok = convert<int16_t>(m, *a, comps, out); break;
	case 5123: ok = convert<uint16_t>(m, *a, comps, out); break;
	case 5125: ok = convert<uint32_t>(m, *a, comps, out); break;
	case 5126: ok = convert<float>(m, *a, comps, out); break;
	default: break;
	}
	if (!ok) say(err, errsize, "its values do not convert to the accessor's componentType");
	return ok ? API_DRACO_OK : API_DRACO_BAD;
}
