// `vkrt info SCENE`: what the scene needs (its FeatureSet), the kernel
// variant that was built for it, and how long it took to get a first frame.
#include "app/Commands.h"
#include "mesh/MeshGeometry.h"
#include "render/RenderSession.h"
#include "texture/TextureAtlas.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <memory>
#include <set>

namespace vkrt {

namespace {

struct InfoOptions {
    std::string scenePath;
    std::string device;
    bool uber = false;
};

double secondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Instances, geometries, triangles, BVH nodes, build times and GPU memory of the meshes.
void printMeshes(const Scene& scene, const GpuSceneStatic& meshData, double parseSeconds)
{
    std::set<const MeshGeometry*> geometries;
    double loadSeconds = 0, buildSeconds = 0;
    uint64_t uniqueTriangles = 0;
    uint32_t deepest = 0;
    for (const Mesh& mesh : scene.meshes) {
        if (!geometries.insert(mesh.geometry.get()).second) continue;
        loadSeconds += mesh.geometry->loadSeconds;
        buildSeconds += mesh.geometry->bvh.buildSeconds;
        uniqueTriangles += mesh.geometry->data.triangles.size();
        deepest = std::max(deepest, mesh.geometry->bvh.depth);
    }
    const size_t topNodes = meshData.top ? meshData.top->bvh.nodes.size() : 0;
    const double bytes = double(meshData.meshNodes.size() * sizeof(gpu::BvhNode) +
                                meshData.meshTriangles.size() * sizeof(gpu::MeshTriangle) +
                                meshData.meshNormals.size() * sizeof(gpu::MeshNormals) +
                                emissiveTriangleCount(scene) * sizeof(gpu::Emitter) + topNodes * sizeof(gpu::BvhNode));
    std::printf("meshes:         %zu instances of %zu files; %llu triangles (%llu rendered), %llu emissive\n",
                scene.meshes.size(), geometries.size(), static_cast<unsigned long long>(uniqueTriangles),
                static_cast<unsigned long long>(meshTriangleCount(scene)),
                static_cast<unsigned long long>(emissiveTriangleCount(scene)));
    std::printf("bvh:            %zu mesh nodes (deepest %u levels), %zu top-level nodes over %zu records\n",
                meshData.meshNodes.size(), deepest, topNodes, meshData.top ? meshData.top->refs.size() : 0);
    std::printf("mesh times:     load %.3f s, BVH build %.3f s (+ top level %.4f s); whole parse %.3f s\n",
                loadSeconds, buildSeconds, meshData.topBuildSeconds, parseSeconds);
    std::printf("mesh memory:    %.1f MiB on the GPU\n", bytes / (1024.0 * 1024.0));
}

/// Distinct images, records (image and wrap modes) and texel memory.
void printTextures(const TextureAtlas& textures)
{
    std::printf("textures:       %zu images, %zu records, %.1f MiB of texels (all mip levels)\n",
                textures.imageCount(), textures.recordCount(), double(textures.texelBytes()) / (1024.0 * 1024.0));
}

int runInfo(const InfoOptions& options)
{
    const auto parseStart = std::chrono::steady_clock::now();
    Scene scene = loadScene(options.scenePath);
    const double parseSeconds = secondsSince(parseStart);
    VulkanContext context({options.device, false});
    SessionConfig config;
    config.uber = options.uber;
    config.warmUp = false; // the first frame's time is what info measures
    // The variant info has always described: independent samples, no variance.
    config.sampler = SamplerChoice::Independent;
    auto start = std::chrono::steady_clock::now();
    RenderSession session(context, scene, config);
    double setupSeconds = secondsSince(start);
    session.renderFrames(1);
    double firstFrameSeconds = secondsSince(start);

    const KernelVariant& features = session.renderer().variant();
    const CompiledKernel& kernel = session.renderer().kernel();
    const RenderOptions& renderOptions = session.renderOptions();
    std::printf("scene:          %s (%ux%u)\n", scene.path.c_str(), scene.camera.width, scene.camera.height);
    std::printf("features:       %s\n", features.describe().c_str());
    std::printf("variant:        %s%s\n", kernel.cacheKey.c_str(), options.uber ? " (uber)" : "");
    std::printf("defines:        %s\n", describeDefines(features.defines()).c_str());
    std::printf("bindings:       %zu\n", features.bindings().size());
    std::printf("spirv bytes:    %zu\n", kernel.spirv.size() * sizeof(uint32_t));
    std::printf("glslang:        %s\n",
                kernel.fromCache ? "cache hit (0 s)" : (std::to_string(kernel.compileSeconds) + " s").c_str());
    std::printf("spirv cache:    %s\n", renderOptions.cacheDirectory.c_str());
    std::printf("set-up:         %.3f s (parse excluded: compile or load, pipeline, buffers)\n", setupSeconds);
    std::printf("first frame:    %.3f s after set-up began (includes the driver's shader compile)\n",
                firstFrameSeconds);
    std::printf("loop cap:       %s\n", context.loopCap().describe().c_str());
    if (scene.meshes.empty())
        std::printf("loop passes:    worst case %llu per invocation%s\n",
                    static_cast<unsigned long long>(worstCaseLoopIterations(scene)),
                    context.loopCap().capped() ? (" of " + std::to_string(*context.loopCap().budget)).c_str() : "");
    else
        std::printf("loop passes:    no static bound (BVH traversal)%s\n",
                    context.loopCap().capped() ? "; each subgroup's count is checked against the cap as it renders"
                                               : "");
    if (!scene.meshes.empty()) printMeshes(scene, session.renderer().meshData(), parseSeconds);
    if (scene.textures) printTextures(*scene.textures);
    std::printf("device:         %s\n", context.deviceInfo().name.c_str());
    return kExitOk;
}

} // namespace

CommandRunner addInfoCommand(CLI::App& app)
{
    auto options = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand("info", "Show a scene's features, its kernel variant and start-up times");
    cmd->add_option("scene", options->scenePath, "Scene file")->required();
    cmd->add_option("--device", options->device, "Vulkan device index or name");
    cmd->add_flag("--uber", options->uber, "Describe the all-features kernel instead");
    return [options] { return runInfo(*options); };
}

} // namespace vkrt
