// The render kernel's sampler over a tile of pixels and a run of frames.
// inputs = image width, tile x0, y0, tile width, tile height, frames, seed.
// Invocation i is frame i % frames of tile pixel i / frames (row-major);
// outputs[8i ..] = its first two sampleNext4D draws (dimensions 0 and 1).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/random.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uint width = uint(inputs[0]);
    uint x0 = uint(inputs[1]);
    uint y0 = uint(inputs[2]);
    uint tileWidth = uint(inputs[3]);
    uint frames = uint(inputs[5]);
    uint seed = uint(inputs[6]);
    uint frame = i % frames;
    uint tilePixel = i / frames;
    uint pixelIndex = (y0 + tilePixel / tileWidth) * width + x0 + tilePixel % tileWidth;
    Sampler rng = samplerCreate(pixelIndex, frame, seed);
    vec4 a = sampleNext4D(rng);
    vec4 b = sampleNext4D(rng);
    for (int k = 0; k < 4; ++k) {
        outputs[8u * i + uint(k)] = a[k];
        outputs[8u * i + 4u + uint(k)] = b[k];
    }
}
