#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
#define UMBRA_SURFACE_SHADING   // pixel shading (renderer/deferred.c): the shading inputs too
#include "surface.glsl"
