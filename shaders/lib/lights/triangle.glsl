// Triangle lights (`type = "triangle"`): black, opaque, emitting triangles.
// A record holds only the geometry rays are tested against; what it emits is
// its Emitter (lib/emitters.glsl), in the one alias table with the emissive
// mesh triangles, so sampling and MIS are those of every emitter.
// Included twice: by lib/scene.glsl for what rays hit, and by lib/lights.glsl
// (VKRT_LIGHT_SAMPLING) for the sampling, which needs the BSDFs and media.
#ifndef VKRT_LIGHT_TRIANGLE_HITS
#define VKRT_LIGHT_TRIANGLE_HITS

#ifdef VKRT_HAS_TRIANGLE_LIGHTS
VKRT_SCENE_ARRAY(BINDING_TRIANGLE_LIGHTS, TriangleLightBlock, TriangleLight, triangleLights, UNIFORM_TRIANGLE_LIGHTS)
#define triangleLights VKRT_SCENE_ITEMS(BINDING_TRIANGLE_LIGHTS, TriangleLightBlock, triangleLights)
#endif

bool hitOneTriangleLight(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    float t;
    vec3 bary;
    TriangleLight light = triangleLights[i];
    if (intersectTriangle(light.v0, light.v1, light.v2, r, tr, tMax, t, bary)) {
        hit = HitId(HIT_TriangleLight, i, t, bary, true, 0u);
        return true;
    }
#endif
    return false;
}

#ifdef VKRT_HAS_TRIANGLE_LIGHTS
VKRT_RECORD_LOOPS(TriangleLight, u.triangleLightCount)
#else
VKRT_NO_RECORDS(TriangleLight)
#endif

void describeTriangleLight(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    // Its counter-clockwise side, as its Emitter's (emitterNormal).
    TriangleLight light = triangleLights[id.index];
    hit.normal = normalize(cross(light.v1 - light.v0, light.v2 - light.v0));
    hit.front = dot(hit.normal, r.dir) < 0.0;
    hit.emitter = light.emitter;
#endif
}

#endif

#if defined(VKRT_LIGHT_SAMPLING) && !defined(VKRT_LIGHT_TRIANGLE_SAMPLING)
#define VKRT_LIGHT_TRIANGLE_SAMPLING

// Sampled with every emitter (lib/emitters.glsl), not on their own: no
// lights of their own to loop over (tableEntriesTriangleLight is 0).
LightArrival whittedSampleTriangleLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng)
{
    return noArrival(origin);
}

LightArrival candidateTriangleLight(uint i, SurfaceHit hit, vec3 ns, vec3 origin, inout Sampler rng, out float pick)
{
    pick = 0.0;
    return noArrival(origin);
}

// No entries of their own in the light table: its last entry is every emitter.
uint tableEntriesTriangleLight() { return 0u; }

LightArrival sampleTableTriangleLight(uint i, float selection, SurfaceHit hit, vec3 ns, vec3 origin, vec4 rnd)
{
    return noArrival(origin);
}


#endif
