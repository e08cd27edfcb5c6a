// Invocation i reads (mode, a, b, c, d) = inputs[5i .. 5i+4]:
//   mode 0: outputs[4i ..] = sampleTexture(uint(a), vec2(b, c), d)
//   mode 1: outputs[4i] = rayConeTextureLod(uint(a), b, c, d) (cone width, cos, uv/world area)
#version 460
#extension GL_GOOGLE_include_directive : require
#define VKRT_HAS_TEXTURES
#include "probe.glsl"
#include "lib/texture.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uint mode = uint(inputs[5 * i]);
    uint textureIndex = uint(inputs[5 * i + 1]);
    vec3 args = vec3(inputs[5 * i + 2], inputs[5 * i + 3], inputs[5 * i + 4]);
    vec4 result = mode == 0u ? sampleTexture(textureIndex, args.xy, args.z)
                             : vec4(rayConeTextureLod(textureIndex, args.x, args.y, args.z), 0.0, 0.0, 0.0);
    for (uint c = 0u; c < 4u; ++c)
        outputs[4 * i + c] = result[c];
}
