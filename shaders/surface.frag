#version 450
#extension GL_GOOGLE_include_directive : require
#include "umbra_shared.h"
#include "surface.glsl"
