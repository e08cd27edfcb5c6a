// Axis-aligned boxes (`shape = "box"`): the records, their slab test
// (lib/intersect.glsl: intersectBox), the face's own coordinate, and uvs.
#ifndef VKRT_SHAPE_BOX_GLSL
#define VKRT_SHAPE_BOX_GLSL

#ifdef VKRT_HAS_BOXES
VKRT_SCENE_ARRAY(BINDING_BOXES, BoxBlock, Box, boxes, UNIFORM_BOXES)
#define boxes VKRT_SCENE_ITEMS(BINDING_BOXES, BoxBlock, boxes)
#endif

bool hitOneBox(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit)
{
#ifdef VKRT_HAS_BOXES
    float t;
    vec3 n;
    bool front;
    if (intersectBox(boxes[i], r, tMax, t, n, front)) {
        hit = HitId(HIT_Box, i, t, n, front, 0u);
        return true;
    }
#endif
    return false;
}

#ifdef VKRT_HAS_BOXES
VKRT_RECORD_LOOPS(Box, u.boxCount)
#else
VKRT_NO_RECORDS(Box)
#endif

#ifdef VKRT_HAS_TEXTURES
// Each face's uv spans [0, 1]^2 over the face, upright seen from outside (v
// up along +y on the side faces; on the top v grows towards -z, on the
// bottom towards +z).
void boxUv(Box b, vec3 faceNormal, vec3 p, inout SurfaceHit hit)
{
    vec3 extent = b.upper - b.lower;
    vec3 f = (p - b.lower) / extent; // 0 ... 1 across the box
    if (faceNormal.x != 0.0) {
        float s = faceNormal.x;
        hit.uv = vec2(s > 0.0 ? 1.0 - f.z : f.z, f.y);
        hit.uvDensity = 1.0 / (extent.z * extent.y);
        hit.tangent = vec4(0.0, 0.0, -s, 1.0);
    } else if (faceNormal.y != 0.0) {
        float s = faceNormal.y;
        hit.uv = vec2(f.x, s > 0.0 ? 1.0 - f.z : f.z);
        hit.uvDensity = 1.0 / (extent.x * extent.z);
        hit.tangent = vec4(1.0, 0.0, 0.0, 1.0);
    } else {
        float s = faceNormal.z;
        hit.uv = vec2(s > 0.0 ? f.x : 1.0 - f.x, f.y);
        hit.uvDensity = 1.0 / (extent.x * extent.y);
        hit.tangent = vec4(s, 0.0, 0.0, 1.0);
    }
}
#endif

void describeBox(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_BOXES
    // The coordinate across the face is the face's own, exactly.
    Box b = boxes[id.index];
    hit.normal = id.detail;
    int axis = id.detail.x != 0.0 ? 0 : (id.detail.y != 0.0 ? 1 : 2);
    hit.position[axis] = id.detail[axis] > 0.0 ? b.upper[axis] : b.lower[axis];
    hit.error[axis] = 0.0;
    hit.material = b.material;
#ifdef VKRT_HAS_TEXTURES
    boxUv(b, id.detail, hit.position, hit);
#endif
#endif
}

#endif
