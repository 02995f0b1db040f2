#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
// mesh.frag taking each light's shadow from the visibility pass (renderer/visibility.c): a
// module of its own, so that the other pipelines never declare that pass's images.
#define UMBRA_VIS_READ
#include "mesh_main.glsl"
