#include "render/GpuScene.h"

#include "shared/Bindings.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace vkrt {

namespace {

glm::vec3 toFloat(const glm::dvec3& v) { return glm::vec3(v); }

/// World -> camera-relative float32.
struct Relativizer {
    glm::dvec3 eye;
    glm::vec3 operator()(const glm::dvec3& p) const { return glm::vec3(p - eye); }
};

gpu::Material convertMaterial(const Material& m, Integrator integrator)
{
    gpu::Material g{};
    g.diffuse = toFloat(m.diffuse);
    g.type = uint32_t(m.type);
    g.specular = toFloat(m.specular);
    g.exponent = float(m.exponent);
    g.absorption = toFloat(m.absorption);
    g.ior = float(m.ior);
    switch (m.fresnel) {
    case FresnelMode::None: g.fresnel = gpu::FRESNEL_NONE; break;
    case FresnelMode::Schlick: g.fresnel = gpu::FRESNEL_SCHLICK; break;
    case FresnelMode::Exact: g.fresnel = gpu::FRESNEL_EXACT; break;
    case FresnelMode::Default:
        // The seed's Whitted renderer uses Schlick for glass; physics wants the exact form.
        if (m.type != MaterialType::Dielectric) g.fresnel = gpu::FRESNEL_NONE;
        else g.fresnel = integrator == Integrator::Path ? gpu::FRESNEL_EXACT : gpu::FRESNEL_SCHLICK;
        break;
    }
    return g;
}

// One conversion per shape and light kind (shared/Kinds.h), found by overload.
gpu::Sphere toGpu(const Sphere& s, const Relativizer& rel) { return {rel(s.center), float(s.radius), s.material}; }
gpu::Box toGpu(const Box& b, const Relativizer& rel) { return {rel(b.min), b.material, rel(b.max)}; }
gpu::Triangle toGpu(const Triangle& t, const Relativizer& rel)
{
    return {rel(t.vertices[0]), t.material, rel(t.vertices[1]), rel(t.vertices[2])};
}
gpu::Plane toGpu(const Plane& p, const Relativizer& rel) { return {rel(p.point), p.material, toFloat(p.normal)}; }
gpu::PointLight toGpu(const PointLight& l, const Relativizer& rel) { return {rel(l.position), toFloat(l.intensity)}; }
gpu::TriangleLight toGpu(const TriangleLight& l, const Relativizer& rel)
{
    double area = triangleArea(l.vertices);
    return {rel(l.vertices[0]),   float(area),        rel(l.vertices[1]),
            l.twoSided ? 1u : 0u, rel(l.vertices[2]), toFloat(l.radiance)};
}

/// The records of a kind that reach the GPU: all of them, except that
/// triangle lights that cannot emit are dropped.
template <class Record>
const std::vector<Record>& recordsToUpload(const Scene&, const std::vector<Record>& all)
{
    return all;
}
std::vector<TriangleLight> recordsToUpload(const Scene& scene, const std::vector<TriangleLight>&)
{
    return emittingTriangleLights(scene);
}

void convertCamera(const Camera& camera, gpu::SceneUniforms& u)
{
    glm::dvec3 forward = glm::normalize(camera.target - camera.eye);
    glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
    glm::dvec3 up = glm::cross(right, forward);
    double halfHeight = std::tan(glm::radians(camera.fovY) / 2.0);
    double halfWidth = halfHeight * double(camera.width) / double(camera.height);
    u.cameraRight = toFloat(right * halfWidth);
    u.cameraUp = toFloat(up * halfHeight);
    u.cameraForward = toFloat(forward);
    u.width = camera.width;
    u.height = camera.height;
}

} // namespace

double triangleArea(const std::array<glm::dvec3, 3>& v)
{
    return 0.5 * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
}

std::vector<TriangleLight> emittingTriangleLights(const Scene& scene)
{
    std::vector<TriangleLight> lights;
    for (const auto& l : scene.triangleLights) {
        double area = triangleArea(l.vertices);
        // A light whose area is zero (or rounds to zero in float) emits nothing.
        if (area > 0.0 && float(area) > 0.0 && std::isfinite(area)) lights.push_back(l);
    }
    return lights;
}

uint32_t tileCountFor(uint32_t width, uint32_t height)
{
    uint32_t tilesX = (width + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
    uint32_t tilesY = (height + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
    return tilesX * tilesY;
}

uint32_t tileStrideFor(uint32_t tileCount)
{
    // Any stride coprime to the count visits every tile once; a prime above
    // lavapipe's thread count sends each thread's run of workgroups across the
    // whole image. Small enough that group * stride fits in 32 bits.
    for (uint32_t stride : {17u, 19u, 23u, 29u, 31u, 37u, 41u, 43u, 47u})
        if (std::gcd(stride, tileCount) == 1 && stride < tileCount) return stride;
    return 1;
}

/// The dielectric objects the eye is inside (spheres, boxes, the back side of
/// planes), outermost first, at most MEDIUM_STACK_DEPTH of the innermost.
/// Decided in double on the world coordinates. Nesting order comes from the
/// distance between the eye and each boundary: for A inside B, the eye is
/// never farther from A's boundary than from B's (the segment to B's nearest
/// point crosses A's boundary). Of identical (coincident) objects only the
/// first counts, as the kernel only ever meets the first of them.
std::vector<uint32_t> mediaAroundCamera(const Scene& scene)
{
    std::vector<std::pair<double, uint32_t>> around; // (distance to the boundary, material)
    auto dielectric = [&](uint32_t m) { return scene.materials[m].type == MaterialType::Dielectric; };
    const glm::dvec3 eye = scene.camera.eye;
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const Sphere& s = scene.spheres[i];
        double depth = s.radius - glm::length(eye - s.center);
        bool repeated = std::any_of(scene.spheres.begin(), scene.spheres.begin() + long(i), [&](const Sphere& o) {
            return dielectric(o.material) && o.center == s.center && o.radius == s.radius;
        });
        if (dielectric(s.material) && depth > 0.0 && !repeated) around.push_back({depth, s.material});
    }
    for (size_t i = 0; i < scene.boxes.size(); ++i) {
        const Box& b = scene.boxes[i];
        glm::dvec3 margin = glm::min(eye - b.min, b.max - eye);
        double depth = std::min(margin.x, std::min(margin.y, margin.z));
        bool repeated = std::any_of(scene.boxes.begin(), scene.boxes.begin() + long(i), [&](const Box& o) {
            return dielectric(o.material) && o.min == b.min && o.max == b.max;
        });
        if (dielectric(b.material) && depth > 0.0 && !repeated) around.push_back({depth, b.material});
    }
    // A dielectric plane bounds a half-space of glass behind its normal.
    for (const auto& p : scene.planes) {
        double depth = -glm::dot(eye - p.point, p.normal);
        if (dielectric(p.material) && depth > 0.0) around.push_back({depth, p.material});
    }
    std::stable_sort(around.begin(), around.end(), [](auto& a, auto& b) { return a.first > b.first; });
    if (around.size() > gpu::MEDIUM_STACK_DEPTH) around.erase(around.begin(), around.end() - gpu::MEDIUM_STACK_DEPTH);
    std::vector<uint32_t> materials;
    for (const auto& entry : around) materials.push_back(entry.second);
    return materials;
}

GpuSceneData convertScene(const Scene& scene, const FrameSettings& settings)
{
    GpuSceneData data;
    Relativizer rel{scene.camera.eye};
    for (const auto& m : scene.materials) data.materials.push_back(convertMaterial(m, scene.render.integrator));
#define VKRT_CONVERT_RECORDS(KIND, Type, name, value, field, array, ARRAY, capacity) \
    for (const auto& record : recordsToUpload(scene, scene.array)) data.array.push_back(toGpu(record, rel));
    VKRT_SHAPE_KINDS(VKRT_CONVERT_RECORDS)
    VKRT_LIGHT_KINDS(VKRT_CONVERT_RECORDS)
#undef VKRT_CONVERT_RECORDS

    gpu::SceneUniforms& u = data.uniforms;
    convertCamera(scene.camera, u);
    u.flags = settings.jitter ? gpu::RENDER_FLAG_JITTER : 0u;
    u.backgroundColor = toFloat(scene.background.color);
    u.maxDepth = uint32_t(scene.render.maxDepth);
#define VKRT_COUNT_RECORDS(KIND, Type, name, value, field, array, ARRAY, capacity) \
    u.field##Count = uint32_t(data.array.size());
    VKRT_SHAPE_KINDS(VKRT_COUNT_RECORDS)
    VKRT_LIGHT_KINDS(VKRT_COUNT_RECORDS)
#undef VKRT_COUNT_RECORDS
    u.tileCount = tileCountFor(u.width, u.height);
    u.tileStride = tileStrideFor(u.tileCount);
    std::vector<uint32_t> media = mediaAroundCamera(scene);
    u.cameraMediumCount = uint32_t(media.size());
    for (size_t i = 0; i < media.size(); ++i) u.cameraMedia[int(i)] = media[i];
    return data;
}

} // namespace vkrt
