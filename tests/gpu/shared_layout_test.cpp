// The C++ view of every GPU struct (shaders/shared) must match the layout
// glslang gives the same struct in the real kernels: compare every member
// offset with glslang's reflection of the all-features kernel.
#include "gpu/ShaderCompiler.h"
#include "render/KernelVariant.h"
#include "shared/Bindings.h"
#include "shared/SceneTypes.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <map>

namespace vkrt::test {
namespace {

std::map<std::string, int> reflectedOffsets()
{
    // Reflection sees the scene's buffers as storage buffers (a variant
    // without sceneAddresses); through device addresses they have the same
    // scalar layout (lib/scene_buffers.glsl).
    KernelSource source{defaultShaderRoot(), "kernels/render.comp",
                        KernelVariant{FeatureSet::everything(Integrator::Whitted)}.defines()};
    std::map<std::string, int> offsets;
    for (const auto& [name, offset] : reflectBlockMemberOffsets(source)) offsets[name] = offset;
    return offsets;
}

struct Member {
    std::string reflectedName; // as glslang names it: element 0 of the array
    size_t offset;             // offsetof in C++ plus the array element's base
};

#define ARRAY_MEMBER(array, Type, field) \
    Member { #array "[0]." #field, offsetof(gpu::Type, field) }
#define BLOCK_MEMBER(instance, Type, field) \
    Member { #instance "." #field, offsetof(gpu::Type, field) }

std::vector<Member> expectedMembers()
{
    return {
        ARRAY_MEMBER(materials, Material, diffuse),
        ARRAY_MEMBER(materials, Material, type),
        ARRAY_MEMBER(materials, Material, specular),
        ARRAY_MEMBER(materials, Material, exponent),
        ARRAY_MEMBER(materials, Material, absorption),
        ARRAY_MEMBER(materials, Material, ior),
        ARRAY_MEMBER(materials, Material, fresnel),
        ARRAY_MEMBER(materials, Material, alphaX),
        ARRAY_MEMBER(materials, Material, alphaY),
        ARRAY_MEMBER(materials, Material, table),
        ARRAY_MEMBER(materials, Material, eta),
        ARRAY_MEMBER(materials, Material, metallic),
        ARRAY_MEMBER(materials, Material, k),
        ARRAY_MEMBER(materials, Material, lobeWeight),
        ARRAY_MEMBER(materials, Material, internalReflectance),
        ARRAY_MEMBER(materials, Material, sheenColor),
        ARRAY_MEMBER(materials, Material, sheenRoughness),
        ARRAY_MEMBER(materials, Material, specularFactor),
        ARRAY_MEMBER(materials, Material, clearcoat),
        ARRAY_MEMBER(materials, Material, clearcoatAlpha),
        ARRAY_MEMBER(materials, Material, transmission),
        ARRAY_MEMBER(materials, Material, pbrFlags),
        ARRAY_MEMBER(materials, Material, iridescence),
        ARRAY_MEMBER(materials, Material, iridescenceIor),
        ARRAY_MEMBER(materials, Material, iridescenceThicknessMin),
        ARRAY_MEMBER(materials, Material, iridescenceThickness),
        ARRAY_MEMBER(materials, Material, anisotropy),
        ARRAY_MEMBER(materials, Material, clearcoatNormal),
        ARRAY_MEMBER(spheres, Sphere, center),
        ARRAY_MEMBER(spheres, Sphere, radius),
        ARRAY_MEMBER(spheres, Sphere, material),
        ARRAY_MEMBER(boxes, Box, lower),
        ARRAY_MEMBER(boxes, Box, material),
        ARRAY_MEMBER(boxes, Box, upper),
        ARRAY_MEMBER(triangles, Triangle, v0),
        ARRAY_MEMBER(triangles, Triangle, material),
        ARRAY_MEMBER(triangles, Triangle, v1),
        ARRAY_MEMBER(triangles, Triangle, v2),
        ARRAY_MEMBER(planes, Plane, point),
        ARRAY_MEMBER(planes, Plane, material),
        ARRAY_MEMBER(planes, Plane, normal),
        ARRAY_MEMBER(meshes, Mesh, toWorld0),
        ARRAY_MEMBER(meshes, Mesh, toWorld2),
        ARRAY_MEMBER(meshes, Mesh, toObject0),
        ARRAY_MEMBER(meshes, Mesh, toObject2),
        ARRAY_MEMBER(meshes, Mesh, material),
        ARRAY_MEMBER(meshes, Mesh, root),
        ARRAY_MEMBER(meshes, Mesh, firstTriangle),
        ARRAY_MEMBER(meshes, Mesh, firstNormals),
        ARRAY_MEMBER(meshes, Mesh, flags),
        ARRAY_MEMBER(meshes, Mesh, firstEmitter),
        ARRAY_MEMBER(meshNodes, BvhNode, lower),
        ARRAY_MEMBER(meshNodes, BvhNode, first),
        ARRAY_MEMBER(meshNodes, BvhNode, upper),
        ARRAY_MEMBER(meshNodes, BvhNode, count),
        ARRAY_MEMBER(meshTriangles, MeshTriangle, v0),
        ARRAY_MEMBER(meshTriangles, MeshTriangle, v1),
        ARRAY_MEMBER(meshTriangles, MeshTriangle, v2),
        ARRAY_MEMBER(meshNormals, MeshNormals, n0),
        ARRAY_MEMBER(meshNormals, MeshNormals, n2),
        ARRAY_MEMBER(emitters, Emitter, v0),
        ARRAY_MEMBER(emitters, Emitter, area),
        ARRAY_MEMBER(emitters, Emitter, twoSided),
        ARRAY_MEMBER(emitters, Emitter, pdf),
        ARRAY_MEMBER(emitters, Emitter, radiance),
        ARRAY_MEMBER(emitters, Emitter, aliasThreshold),
        ARRAY_MEMBER(emitters, Emitter, alias),
        ARRAY_MEMBER(emitters, Emitter, textures),
        ARRAY_MEMBER(emitters, Emitter, uvs),
        ARRAY_MEMBER(pointLights, PointLight, position),
        ARRAY_MEMBER(pointLights, PointLight, intensity),
        ARRAY_MEMBER(triangleLights, TriangleLight, v0),
        ARRAY_MEMBER(triangleLights, TriangleLight, emitter),
        ARRAY_MEMBER(triangleLights, TriangleLight, v1),
        ARRAY_MEMBER(triangleLights, TriangleLight, v2),
        ARRAY_MEMBER(directionalLights, DirectionalLight, toLight),
        ARRAY_MEMBER(directionalLights, DirectionalLight, oneMinusCos),
        ARRAY_MEMBER(directionalLights, DirectionalLight, radiance),
        ARRAY_MEMBER(directionalLights, DirectionalLight, sin2Alpha),
        ARRAY_MEMBER(spotLights, SpotLight, position),
        ARRAY_MEMBER(spotLights, SpotLight, cosOuter),
        ARRAY_MEMBER(spotLights, SpotLight, intensity),
        ARRAY_MEMBER(spotLights, SpotLight, falloffScale),
        ARRAY_MEMBER(spotLights, SpotLight, axis),
        ARRAY_MEMBER(materialAlpha, MaterialAlpha, mode),
        ARRAY_MEMBER(materialAlpha, MaterialAlpha, cutoff),
        ARRAY_MEMBER(materialAlpha, MaterialAlpha, alpha),
        ARRAY_MEMBER(accum, AccumPixel, sum),
        ARRAY_MEMBER(accum, AccumPixel, count),
        ARRAY_MEMBER(accum, AccumPixel, compensation),
        BLOCK_MEMBER(stats, RenderStats, maxLoopIterations),
        BLOCK_MEMBER(stats, RenderStats, budgetExceeded),
        BLOCK_MEMBER(u, SceneUniforms, cameraRight),
        BLOCK_MEMBER(u, SceneUniforms, width),
        BLOCK_MEMBER(u, SceneUniforms, cameraUp),
        BLOCK_MEMBER(u, SceneUniforms, height),
        BLOCK_MEMBER(u, SceneUniforms, cameraForward),
        BLOCK_MEMBER(u, SceneUniforms, flags),
        BLOCK_MEMBER(u, SceneUniforms, backgroundColor),
        BLOCK_MEMBER(u, SceneUniforms, maxDepth),
        BLOCK_MEMBER(u, SceneUniforms, sphereCount),
        BLOCK_MEMBER(u, SceneUniforms, boxCount),
        BLOCK_MEMBER(u, SceneUniforms, triangleCount),
        BLOCK_MEMBER(u, SceneUniforms, planeCount),
        BLOCK_MEMBER(u, SceneUniforms, meshCount),
        BLOCK_MEMBER(u, SceneUniforms, pointLightCount),
        BLOCK_MEMBER(u, SceneUniforms, triangleLightCount),
        BLOCK_MEMBER(u, SceneUniforms, tileCount),
        BLOCK_MEMBER(u, SceneUniforms, tileStride),
        BLOCK_MEMBER(u, SceneUniforms, environmentSize),
        BLOCK_MEMBER(u, SceneUniforms, cameraMediumCount),
        BLOCK_MEMBER(u, SceneUniforms, cameraMedia),
        BLOCK_MEMBER(u, SceneUniforms, emitterCount),
        BLOCK_MEMBER(u, SceneUniforms, topNodeCount),
        BLOCK_MEMBER(u, SceneUniforms, apertureRadius),
        BLOCK_MEMBER(u, SceneUniforms, focusDistance),
        BLOCK_MEMBER(u, SceneUniforms, environmentExtent),
        BLOCK_MEMBER(u, SceneUniforms, environmentGrid),
        BLOCK_MEMBER(u, SceneUniforms, environmentBlock),
        BLOCK_MEMBER(u, SceneUniforms, environmentAxisX),
        BLOCK_MEMBER(u, SceneUniforms, environmentAxisZ),
        BLOCK_MEMBER(u, SceneUniforms, softDirectionalLightCount),
        BLOCK_MEMBER(u, SceneUniforms, lightTableCount),
        BLOCK_MEMBER(u, SceneUniforms, lightCandidates),
        BLOCK_MEMBER(u, SceneUniforms, bufferAddresses),
        ARRAY_MEMBER(lightTable, LightPick, pdf),
        ARRAY_MEMBER(lightTable, LightPick, aliasThreshold),
        ARRAY_MEMBER(lightTable, LightPick, alias),
        BLOCK_MEMBER(frame, FrameConstants, firstFrame),
        BLOCK_MEMBER(frame, FrameConstants, seed),
    };
}

TEST(SharedLayout, EveryMemberOffsetMatchesGlslangReflection)
{
    auto offsets = reflectedOffsets();
    std::string names;
    for (const auto& [name, offset] : offsets) names += name + "@" + std::to_string(offset) + " ";
    for (const Member& m : expectedMembers()) {
        auto it = offsets.find(m.reflectedName);
        ASSERT_NE(it, offsets.end()) << m.reflectedName << " not reflected; glslang reported: " << names;
        EXPECT_EQ(size_t(it->second), m.offset) << m.reflectedName;
    }
}

// Each struct ends right after its last member (no tail padding on either side).
TEST(SharedLayout, LastMemberEndsTheStruct)
{
    auto offsets = reflectedOffsets();
    // glslang reports runtime arrays by their first element only; the
    // stride is the struct size in the scalar layout, which static_asserts in
    // src/gpu/SharedTypes.cpp pin. Here check the last member ends the struct.
    EXPECT_EQ(offsets.at("spheres[0].material") + 4, int(sizeof(gpu::Sphere)));
    EXPECT_EQ(offsets.at("materials[0].clearcoatNormal") + 12, int(sizeof(gpu::Material)));
    EXPECT_EQ(offsets.at("triangleLights[0].v2") + 12, int(sizeof(gpu::TriangleLight)));
    EXPECT_EQ(offsets.at("u.bufferAddresses") + 8 * int(gpu::ADDRESSED_BINDING_COUNT), int(sizeof(gpu::SceneUniforms)));
    EXPECT_EQ(offsets.at("lightTable[0].alias") + 4, int(sizeof(gpu::LightPick)));
    EXPECT_EQ(offsets.at("directionalLights[0].sin2Alpha") + 4, int(sizeof(gpu::DirectionalLight)));
    EXPECT_EQ(offsets.at("spotLights[0].axis") + 12, int(sizeof(gpu::SpotLight)));
    EXPECT_EQ(offsets.at("meshes[0].firstEmitter") + 4, int(sizeof(gpu::Mesh)));
    EXPECT_EQ(offsets.at("emitters[0].uvs") + 4, int(sizeof(gpu::Emitter)));
    EXPECT_EQ(offsets.at("materialAlpha[0].alpha") + 4, int(sizeof(gpu::MaterialAlpha)));
}

} // namespace
} // namespace vkrt::test
