// Tone-maps the running mean of the accumulation buffer into an 8-bit sRGB
// image for the viewer: radiance * 2^exposure, clamped (or the filmic curve),
// sRGB-encoded exactly as src/io/PngFile.cpp does for PNG files.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

#include "shared/Bindings.h"
#include "shared/Display.h"
#include "shared/SceneTypes.h"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;
layout(scalar, binding = DISPLAY_BINDING_ACCUMULATION) readonly buffer AccumBlock { AccumPixel accum[]; };
layout(rgba8, binding = DISPLAY_BINDING_OUTPUT) uniform writeonly image2D displayImage;
layout(push_constant, scalar) uniform PushBlock { DisplayConstants display; };

vec3 acesFilmic(vec3 x) { return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); }

float srgbEncode(float v)
{
    v = clamp(v, 0.0, 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

void main()
{
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= display.width || pixel.y >= display.height)
        return;
    // Band b of the image (render/ImageBands.h) is dispatched at base
    // workgroup y = b * gl_NumWorkGroups.y and has a buffer of its own rows.
    uint bandFirstRow = (gl_WorkGroupID.y - gl_WorkGroupID.y % gl_NumWorkGroups.y) * WORKGROUP_SIZE_Y;
    AccumPixel p = accum[(pixel.y - bandFirstRow) * display.width + pixel.x];
    vec3 mean = p.count > 0u ? (p.sum - p.compensation) / float(p.count) : vec3(0.0);
    vec3 exposed = max(mean * display.exposureScale, vec3(0.0)); // also maps NaN to 0
    vec3 mapped = display.toneMapper == TONE_MAP_FILMIC ? acesFilmic(exposed) : min(exposed, vec3(1.0));
    vec3 encoded = vec3(srgbEncode(mapped.r), srgbEncode(mapped.g), srgbEncode(mapped.b));
    imageStore(displayImage, ivec2(pixel), vec4(encoded, 1.0));
}
