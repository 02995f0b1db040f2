/*
 * tests/util/draco_encode — a mesh through libdraco's encoder (see the header).
 */
#include <cstdlib>
#include <cstring>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include "draco_encode.h"

static size_t type_size(int dt)
{
	return dt == TEST_DRACO_FLOAT32 ? 4 : 2;
}

static bool add_attributes(draco::Mesh &mesh, struct test_draco_attr *attrs, int nattrs, uint32_t nv)
{
	for (int a = 0; a < nattrs; a++) {
		draco::GeometryAttribute ga;
		size_t vsize = type_size(attrs[a].data_type) * static_cast<size_t>(attrs[a].comps);
		ga.Init(static_cast<draco::GeometryAttribute::Type>(attrs[a].type), nullptr,
		        static_cast<uint8_t>(attrs[a].comps), static_cast<draco::DataType>(attrs[a].data_type), false,
		        static_cast<int64_t>(vsize), 0);
		int id = mesh.AddAttribute(ga, true, nv);
		if (id < 0) return false;
		draco::PointAttribute *pa = mesh.attribute(id);
		const uint8_t *v = static_cast<const uint8_t *>(attrs[a].values);
		for (uint32_t i = 0; i < nv; i++) pa->SetAttributeValue(draco::AttributeValueIndex(i), v + i * vsize);
		attrs[a].unique_id = pa->unique_id();
	}
	return true;
}

extern "C" uint8_t *test_draco_encode(struct test_draco_attr *attrs, int nattrs, uint32_t nv, const uint32_t *idx,
                                      uint32_t ntri, int edgebreaker, int position_bits, size_t *len,
                                      uint32_t *points, uint32_t *faces)
{
	draco::Mesh mesh;
	mesh.set_num_points(nv);
	for (uint32_t t = 0; t < ntri; t++)
		mesh.AddFace({draco::PointIndex(idx[3 * t]), draco::PointIndex(idx[3 * t + 1]), draco::PointIndex(idx[3 * t + 2])});
	if (!add_attributes(mesh, attrs, nattrs, nv)) return nullptr;
	draco::Encoder enc;
	enc.SetEncodingMethod(edgebreaker ? draco::MESH_EDGEBREAKER_ENCODING : draco::MESH_SEQUENTIAL_ENCODING);
	if (position_bits) enc.SetAttributeQuantization(draco::GeometryAttribute::POSITION, position_bits);
	draco::EncoderBuffer buf;
	if (!enc.EncodeMeshToBuffer(mesh, &buf).ok()) return nullptr;
	/* What a decoder makes of it: the counts the glTF accessors must state. */
	draco::DecoderBuffer in;
	in.Init(buf.data(), buf.size());
	draco::Decoder dec;
	auto r = dec.DecodeMeshFromBuffer(&in);
	if (!r.ok()) return nullptr;
	*points = r.value()->num_points();
	*faces = r.value()->num_faces();
	uint8_t *out = static_cast<uint8_t *>(std::malloc(buf.size()));
	if (!out) return nullptr;
	std::memcpy(out, buf.data(), buf.size());
	*len = buf.size();
	return out;
}
