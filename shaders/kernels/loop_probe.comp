#version 460
// Loop-cap probe (src/gpu/LoopCap.cpp): one group of 8 invocations runs a loop
// of `passes` passes and counts, with an atomic the compiler cannot fold away,
// how many passes ran. lavapipe before Mesa 25 ends the loop at 65,535.
layout(local_size_x = 8) in;

layout(push_constant) uniform ProbeConstants { uint passes; } probe;
layout(std430, set = 0, binding = 0) buffer Completed { uint completed[8]; };

void main()
{
    for (uint i = 0u; i < probe.passes; ++i)
        atomicAdd(completed[gl_LocalInvocationID.x], 1u);
}
