#pragma once
// The validated, in-memory scene. Everything here is in double precision and in
// world space; conversion to the GPU's float32, camera-relative form happens in
// render/SceneUpload. A Scene is only ever produced by parseScene*, which has
// already checked every value, so consumers need not re-validate.
#include "util/Error.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

using Color = glm::dvec3; ///< linear RGB

/// Documented hard limits of the scene format (docs/scene-format.md).
struct SceneLimits {
    static constexpr uint32_t maxImageSide = 16384;
    static constexpr uint64_t maxImagePixels = 64ull * 1024 * 1024;
    static constexpr int maxDepth = 64;
    static constexpr double maxIor = 1e30;
};

enum class Integrator { Whitted, Path };

struct RenderSettings {
    Integrator integrator = Integrator::Whitted;
    int maxDepth = 5; ///< longest path (camera ray = depth 1)
};

/// Pinhole camera; fovY is the full vertical field of view in degrees.
struct Camera {
    glm::dvec3 eye{0, 0, 0};
    glm::dvec3 target{0, 0, -1};
    glm::dvec3 up{0, 1, 0};
    double fovY = 45.0;
    uint32_t width = 640;
    uint32_t height = 480;
};

enum class MaterialType { Lambert, Phong, Mirror, Glossy, Dielectric };

/// How reflection strength depends on angle. Default lets the integrator pick
/// (Whitted: Schlick for dielectrics, none otherwise; path: exact for dielectrics).
enum class FresnelMode { Default, None, Schlick, Exact };

struct Material {
    std::string name;
    MaterialType type = MaterialType::Lambert;
    Color diffuse{0.8};     ///< lambert `albedo`, phong `diffuse`
    Color specular{0.0};    ///< phong `specular`; mirror/glossy `reflectance`
    double exponent = 0.0;  ///< phong `shininess`, glossy `exponent`
    double ior = 1.5;       ///< dielectric IOR; also Schlick's R0 for mirror/glossy
    Color absorption{0.0};  ///< dielectric Beer–Lambert κ per unit length
    FresnelMode fresnel = FresnelMode::Default;
    SourceLocation where;   ///< the [materials.NAME] table
};

struct Sphere {
    glm::dvec3 center;
    double radius;
    uint32_t material;
};

/// Axis-aligned box.
struct Box {
    glm::dvec3 min;
    glm::dvec3 max;
    uint32_t material;
};

struct Triangle {
    std::array<glm::dvec3, 3> vertices;
    uint32_t material;
};

/// Infinite plane through `point` with unit `normal`.
struct Plane {
    glm::dvec3 point;
    glm::dvec3 normal;
    uint32_t material;
};

/// Isotropic point light; intensity is radiant intensity (W/sr) per channel.
struct PointLight {
    glm::dvec3 position;
    Color intensity;
};

/// Triangular area light of constant emitted radiance. It emits on the side its
/// vertex winding faces (counter-clockwise seen from the lit side) unless twoSided.
struct TriangleLight {
    std::array<glm::dvec3, 3> vertices;
    Color radiance;
    bool twoSided = false;
};

/// Six cubemap faces, paths resolved relative to the scene file.
struct Cubemap {
    /// +x, -x, +y, -y, +z, -z (Vulkan cube face order)
    std::array<std::string, 6> facePaths;
    SourceLocation where;
};

struct Background {
    Color color{0.0};               ///< constant radiance when there is no cubemap
    std::optional<Cubemap> cubemap; ///< environment radiance from six faces
};

struct Scene {
    std::string path;      ///< the file it came from ("<string>" for text)
    uint64_t fileHash = 0; ///< FNV-1a 64 of the file's bytes
    RenderSettings render;
    Camera camera;
    std::vector<Material> materials;
    std::vector<Sphere> spheres;
    std::vector<Box> boxes;
    std::vector<Triangle> triangles;
    std::vector<Plane> planes;
    std::vector<PointLight> pointLights;
    std::vector<TriangleLight> triangleLights;
    Background background;

    size_t primitiveCount() const { return spheres.size() + boxes.size() + triangles.size() + planes.size(); }
};

} // namespace vkrt
