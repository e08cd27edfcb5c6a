// `vkrt info SCENE`: what the scene needs (its FeatureSet), the kernel
// variant that was built for it, and how long it took to get a first frame.
// `--json` writes the same facts as one JSON object (docs/machine-output.md).
#include "app/Commands.h"
#include "app/JsonOutput.h"
#include "io/AtomicFile.h"
#include "mesh/MeshGeometry.h"
#include "render/RenderSession.h"
#include "scene/FeatureSet.h"
#include "scene/SceneExport.h"
#include "scene/SceneInputs.h"
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
    bool staged = false;
    AccelChoice accel = AccelChoice::Auto;
    SceneReads sceneReads = SceneReads::Auto;
    std::string json;                  ///< --json FILE, or "-" for standard output
    std::string sceneJson;             ///< --scene-json FILE, or "-" for standard output
    uint64_t maxTextureChunkBytes = 0; ///< test hook: texel buffers of at most this many bytes
};

/// --scene-json as an output for the checks ("-" is no file).
NamedFile sceneJsonFile(const std::string& path) { return {"--scene-json", path == "-" ? "" : path}; }

/// `--scene-json`: the parsed scene (docs/scene-json.md); info stops there, before making a device.
int writeSceneJson(const Scene& scene, const std::string& path)
{
    const std::string text = exportSceneText(scene);
    if (path != "-") {
        writeBytesAtomically(path, text);
        return kExitOk;
    }
    if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
        throw InputError("--scene-json: cannot write to standard output");
    return kExitOk;
}

double secondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// How long each step took (seconds).
struct InfoTimes {
    double parse = 0.0;
    double setup = 0.0;      ///< compile or load, pipeline, buffers
    double firstFrame = 0.0; ///< from set-up's start to the first finished frame
    /// What a camera move costs before the next frame (the viewer's stall):
    /// the scene re-made camera-relative and uploaded, and with the driver
    /// backend its camera-relative structures rebuilt.
    double cameraMove = 0.0;
};

// ---------------------------------------------------------------- counts

/// Records of each shape, light and material kind, by the scene file's names.
struct KindCounts {
    std::vector<std::pair<std::string, size_t>> shapes, lights, materials;
};

KindCounts kindCounts(const Scene& scene)
{
    KindCounts counts;
    for (ShapeKind kind : kAllShapeKinds) counts.shapes.emplace_back(kindName(kind), scene.count(kind));
    for (LightKind kind : kAllLightKinds) counts.lights.emplace_back(kindName(kind), scene.count(kind));
    for (MaterialType type : kAllMaterialTypes) {
        size_t n = 0;
        for (const Material& material : scene.materials) n += material.type == type;
        counts.materials.emplace_back(kindName(type), n);
    }
    return counts;
}

/// "sphere 3, plane 1", the kinds present only ("none" without any).
std::string describeCounts(const std::vector<std::pair<std::string, size_t>>& counts)
{
    std::string text;
    for (const auto& [name, n] : counts)
        if (n) text += (text.empty() ? "" : ", ") + name + " " + std::to_string(n);
    return text.empty() ? "none" : text;
}

JsonObject countsJson(const std::vector<std::pair<std::string, size_t>>& counts)
{
    JsonObject json = JsonObject::object();
    for (const auto& [name, n] : counts) json[name] = n;
    return json;
}

// ---------------------------------------------------------------- meshes

/// Instances, geometries, triangles, BVH nodes, build times and GPU memory of the meshes.
struct MeshFacts {
    size_t instances = 0, geometries = 0;
    uint64_t triangles = 0; ///< of the distinct geometries
    uint64_t renderedTriangles = 0, emissiveTriangles = 0;
    size_t meshNodes = 0;
    uint32_t deepest = 0;
    size_t topNodes = 0, topRecords = 0;
    double loadSeconds = 0.0, buildSeconds = 0.0, topBuildSeconds = 0.0;
    uint64_t gpuBytes = 0;
};

MeshFacts meshFacts(const Scene& scene, const GpuSceneStatic& meshData)
{
    MeshFacts facts;
    std::set<const MeshGeometry*> geometries;
    for (const Mesh& mesh : scene.meshes) {
        if (!geometries.insert(mesh.geometry.get()).second) continue;
        facts.loadSeconds += mesh.geometry->loadSeconds;
        facts.buildSeconds += mesh.geometry->bvh.buildSeconds;
        facts.triangles += mesh.geometry->data.triangles.size();
        facts.deepest = std::max(facts.deepest, mesh.geometry->bvh.depth);
    }
    facts.instances = scene.meshes.size();
    facts.geometries = geometries.size();
    facts.renderedTriangles = meshTriangleCount(scene);
    facts.emissiveTriangles = emissiveTriangleCount(scene);
    facts.meshNodes = meshData.meshNodes.size();
    facts.topNodes = meshData.top ? meshData.top->bvh.nodes.size() : 0;
    facts.topRecords = meshData.top ? meshData.top->refs.size() : 0;
    facts.topBuildSeconds = meshData.topBuildSeconds;
    facts.gpuBytes = meshData.meshNodes.size() * sizeof(gpu::BvhNode) +
                     meshData.meshTriangles.size() * sizeof(gpu::MeshTriangle) +
                     meshData.meshNormals.size() * sizeof(gpu::MeshNormals) +
                     facts.emissiveTriangles * sizeof(gpu::Emitter) + facts.topNodes * sizeof(gpu::BvhNode);
    return facts;
}

void printMeshes(std::FILE* out, const MeshFacts& facts, double parseSeconds)
{
    std::fprintf(out, "meshes:         %zu instances of %zu files; %llu triangles (%llu rendered), %llu emissive\n",
                 facts.instances, facts.geometries, static_cast<unsigned long long>(facts.triangles),
                 static_cast<unsigned long long>(facts.renderedTriangles),
                 static_cast<unsigned long long>(facts.emissiveTriangles));
    std::fprintf(out, "bvh:            %zu mesh nodes (deepest %u levels), %zu top-level nodes over %zu records\n",
                 facts.meshNodes, facts.deepest, facts.topNodes, facts.topRecords);
    std::fprintf(out, "mesh times:     load %.3f s, BVH build %.3f s (+ top level %.4f s); whole parse %.3f s\n",
                 facts.loadSeconds, facts.buildSeconds, facts.topBuildSeconds, parseSeconds);
    std::fprintf(out, "mesh memory:    %.1f MiB on the GPU\n", double(facts.gpuBytes) / (1024.0 * 1024.0));
}

JsonObject meshJson(const MeshFacts& facts)
{
    return {{"instances", facts.instances},
            {"geometries", facts.geometries},
            {"triangles", facts.triangles},
            {"renderedTriangles", facts.renderedTriangles},
            {"emissiveTriangles", facts.emissiveTriangles},
            {"bvhNodes", facts.meshNodes},
            {"bvhDepth", facts.deepest},
            {"topLevelNodes", facts.topNodes},
            {"topLevelRecords", facts.topRecords},
            {"loadSeconds", facts.loadSeconds},
            {"buildSeconds", facts.buildSeconds},
            {"topLevelBuildSeconds", facts.topBuildSeconds},
            {"gpuBytes", facts.gpuBytes}};
}

// ---------------------------------------------------------------- textures

/// Distinct images, records (image and wrap modes), texel memory and the storage buffers it takes.
void printTextures(std::FILE* out, const TextureAtlas& textures, const TextureChunking& chunking)
{
    std::fprintf(out, "textures:       %zu images, %zu records, %.1f MiB of texels (all mip levels) in %u %s\n",
                 textures.imageCount(), textures.recordCount(), double(textures.texelBytes()) / (1024.0 * 1024.0),
                 chunking.count, chunking.count == 1 ? "buffer" : "buffers");
}

/// Bytes of each texel buffer but the last (all of them in one).
uint64_t textureBufferBytes(const TextureAtlas& textures, const TextureChunking& chunking)
{
    return chunking.count == 1 ? textures.texelBytes() : uint64_t(4) << chunking.shift;
}

JsonObject texturesJson(const TextureAtlas& textures, const TextureChunking& chunking)
{
    return {{"images", textures.imageCount()},
            {"records", textures.recordCount()},
            {"texelBytes", textures.texelBytes()},
            {"buffers", chunking.count},
            {"bufferBytes", textureBufferBytes(textures, chunking)}};
}

// ---------------------------------------------------------------- start-up

/// Where a cold or warm start goes, each part once (seconds, wall).
struct StartupSplit {
    double parse = 0.0;    ///< reading the scene, besides the three below
    double textures = 0.0; ///< decoding images or reading them from the texture cache (in parallel)
    uint32_t texturesDecoded = 0, texturesFromCache = 0;
    double meshLoad = 0.0;   ///< reading mesh files
    double bvh = 0.0;        ///< mesh BVHs and the top level
    double glslang = 0.0;    ///< compiling the kernel to SPIR-V (0 from the cache)
    double setup = 0.0;      ///< buffers, pipeline, uploads: set-up besides glslang and the top level
    double firstFrame = 0.0; ///< from set-up's end to the first frame: on lavapipe, its compile of the kernel
    double total() const { return parse + textures + meshLoad + bvh + glslang + setup + firstFrame; }
};

StartupSplit startupSplit(const RenderSession& session, const InfoTimes& times)
{
    const Scene& scene = session.scene();
    StartupSplit split;
    if (scene.textures) {
        const TextureLoadStats& load = scene.textures->loadStats();
        split.textures = load.seconds;
        split.texturesDecoded = load.decoded;
        split.texturesFromCache = load.fromCache;
    }
    double topBuild = 0.0;
    if (!scene.meshes.empty()) {
        const MeshFacts facts = meshFacts(scene, session.renderer().meshData());
        split.meshLoad = facts.loadSeconds;
        split.bvh = facts.buildSeconds + facts.topBuildSeconds;
        topBuild = facts.topBuildSeconds;
    }
    split.parse = std::max(0.0, times.parse - split.textures - split.meshLoad - (split.bvh - topBuild));
    // Both stages' glslang time with staged kernels (the trace stage's is 0 otherwise).
    split.glslang = session.renderer().kernel().compileSeconds + session.renderer().traceStage().compileSeconds;
    split.setup = std::max(0.0, times.setup - split.glslang - topBuild);
    split.firstFrame = std::max(0.0, times.firstFrame - times.setup);
    return split;
}

void printStartup(std::FILE* out, const StartupSplit& s)
{
    std::fprintf(out,
                 "start-up:       %.3f s: parse %.3f, textures %.3f (%u decoded, %u from the texture cache), mesh "
                 "files %.3f, BVH %.3f, glslang %.3f, set-up %.3f, first frame %.3f (the driver's compile and "
                 "one frame)\n",
                 s.total(), s.parse, s.textures, s.texturesDecoded, s.texturesFromCache, s.meshLoad, s.bvh, s.glslang,
                 s.setup, s.firstFrame);
}

JsonObject startupJson(const StartupSplit& s)
{
    return {{"parseSeconds", s.parse},
            {"texturesSeconds", s.textures},
            {"texturesDecoded", s.texturesDecoded},
            {"texturesFromCache", s.texturesFromCache},
            {"meshFilesSeconds", s.meshLoad},
            {"bvhSeconds", s.bvh},
            {"glslangSeconds", s.glslang},
            {"setupSeconds", s.setup},
            {"firstFrameSeconds", s.firstFrame},
            {"totalSeconds", s.total()}};
}

// ---------------------------------------------------------------- the whole report

/// The worst-case loop passes of one invocation; none for meshes (BVH traversal has no static bound).
std::optional<uint64_t> staticLoopBound(const Scene& scene)
{
    if (!scene.meshes.empty()) return std::nullopt;
    return worstCaseLoopIterations(scene);
}

void printLoopPasses(std::FILE* out, const Scene& scene, const LoopCap& cap)
{
    if (const std::optional<uint64_t> bound = staticLoopBound(scene))
        std::fprintf(out, "loop passes:    worst case %llu per invocation%s\n", static_cast<unsigned long long>(*bound),
                     cap.capped() ? (" of " + std::to_string(*cap.budget)).c_str() : "");
    else
        std::fprintf(out, "loop passes:    no static bound (BVH traversal)%s\n",
                     cap.capped() ? "; each subgroup's count is checked against the cap as it renders" : "");
}

/// The traversal backend, and the driver's structures when they are used.
void printAccel(std::FILE* out, const RenderSession& session)
{
    const DriverAccel* accel = session.renderer().driverAccel();
    if (!accel) {
        std::fprintf(out, "traversal:      own (vkrt's BVH in the kernel)\n");
        return;
    }
    std::fprintf(out, "traversal:      driver (VK_KHR_ray_query): structures built in %.3f s, %.1f MiB\n",
                 accel->buildSeconds(), double(accel->storageBytes()) / (1024.0 * 1024.0));
}

JsonObject accelJson(const RenderSession& session)
{
    const DriverAccel* accel = session.renderer().driverAccel();
    if (!accel) return {{"backend", "own"}};
    return {{"backend", "driver"}, {"buildSeconds", accel->buildSeconds()}, {"storageBytes", accel->storageBytes()}};
}

void printInfo(std::FILE* out, const RenderSession& session, const InfoOptions& options, const InfoTimes& times)
{
    const Scene& scene = session.scene();
    const KernelVariant& features = session.renderer().variant();
    const CompiledKernel& kernel = session.renderer().kernel();
    const KindCounts counts = kindCounts(scene);
    std::fprintf(out, "scene:          %s (%ux%u)\n", scene.path.c_str(), scene.camera.width, scene.camera.height);
    std::fprintf(out, "features:       %s\n", features.describe().c_str());
    std::fprintf(out, "objects:        %s; lights: %s; materials: %s\n", describeCounts(counts.shapes).c_str(),
                 describeCounts(counts.lights).c_str(), describeCounts(counts.materials).c_str());
    std::fprintf(out, "variant:        %s%s\n", kernel.cacheKey.c_str(), options.uber ? " (uber)" : "");
    std::fprintf(out, "defines:        %s\n", describeDefines(features.defines()).c_str());
    std::fprintf(out, "bindings:       %zu\n", features.bindings().size());
    std::fprintf(out, "spirv bytes:    %zu\n", kernel.spirv.size() * sizeof(uint32_t));
    std::fprintf(out, "glslang:        %s\n",
                 kernel.fromCache ? "cache hit (0 s)" : (std::to_string(kernel.compileSeconds) + " s").c_str());
    std::fprintf(out, "spirv cache:    %s\n", session.renderOptions().cacheDirectory.c_str());
    std::fprintf(out, "set-up:         %.3f s (parse excluded: compile or load, pipeline, buffers)\n", times.setup);
    std::fprintf(out, "first frame:    %.3f s after set-up began (includes the driver's shader compile)\n",
                 times.firstFrame);
    printStartup(out, startupSplit(session, times));
    std::fprintf(out, "loop cap:       %s\n", session.context().loopCap().describe().c_str());
    printAccel(out, session);
    std::fprintf(out, "camera move:    %.4f s (the viewer's pause per move: re-upload%s)\n", times.cameraMove,
                 session.renderer().driverAccel() ? ", driver structures rebuilt" : "");
    printLoopPasses(out, scene, session.context().loopCap());
    if (!scene.meshes.empty()) printMeshes(out, meshFacts(scene, session.renderer().meshData()), times.parse);
    if (scene.textures) printTextures(out, *scene.textures, session.renderer().meshData().textures.chunking);
    std::fprintf(out, "device:         %s\n", session.context().deviceInfo().name.c_str());
}

/// What the kernel was built for: the scene's kinds (every kind with --uber) and other features.
JsonObject featuresJson(const KernelVariant& variant)
{
    const FeatureSet& features = variant.features;
    JsonObject shapes = JsonObject::array(), lights = JsonObject::array(), materials = JsonObject::array();
    for (ShapeKind kind : kAllShapeKinds)
        if (features.has(kind)) shapes.push_back(kindName(kind));
    for (LightKind kind : kAllLightKinds)
        if (features.has(kind)) lights.push_back(kindName(kind));
    for (MaterialType type : kAllMaterialTypes)
        if (features.has(type)) materials.push_back(kindName(type));
    return {{"description", variant.describe()},
            {"integrator", integratorName(features.integrator)},
            {"shapes", shapes},
            {"lights", lights},
            {"materials", materials},
            {"cubemap", features.cubemap},
            {"environmentSampling", features.environmentSampling},
            {"meshNormals", features.meshNormals},
            {"emitters", features.emitters},
            {"textures", features.textures},
            {"normalMaps", features.normalMaps},
            {"emissionTextures", features.emissionTextures},
            {"fileMaterials", features.fileMaterials}};
}

/// Staged kernels (--staged): the trace stage's SPIR-V (`kernel` itself is the shade stage); null otherwise.
JsonObject traceStageJson(const Renderer& renderer)
{
    if (!renderer.variant().staged) return nullptr;
    const CompiledKernel& trace = renderer.traceStage();
    return {{"cacheKey", trace.cacheKey},
            {"spirvBytes", trace.spirv.size() * sizeof(uint32_t)},
            {"fromCache", trace.fromCache},
            {"compileSeconds", trace.compileSeconds}};
}

JsonObject kernelJson(const RenderSession& session, const InfoOptions& options)
{
    const KernelVariant& variant = session.renderer().variant();
    const CompiledKernel& kernel = session.renderer().kernel();
    JsonObject defines = JsonObject::object();
    for (const auto& [name, value] : variant.defines()) defines[name] = value;
    return {{"cacheKey", kernel.cacheKey},
            {"uber", options.uber},
            {"defines", defines},
            {"bindings", variant.bindings().size()},
            {"spirvBytes", kernel.spirv.size() * sizeof(uint32_t)},
            {"fromCache", kernel.fromCache},
            {"compileSeconds", kernel.compileSeconds},
            {"cacheDirectory", session.renderOptions().cacheDirectory.string()},
            {"staged", variant.staged},
            {"sceneAddresses", variant.sceneAddresses},
            {"traceStage", traceStageJson(session.renderer())}};
}

JsonObject infoJson(const RenderSession& session, const InfoOptions& options, const InfoTimes& times)
{
    const Scene& scene = session.scene();
    const LoopCap& cap = session.context().loopCap();
    const KindCounts counts = kindCounts(scene);
    JsonObject json = jsonDocument("info");
    json["scene"] = scene.path;
    json["width"] = scene.camera.width;
    json["height"] = scene.camera.height;
    json["device"] = {{"name", session.context().deviceInfo().name}, {"driver", session.context().deviceInfo().driver}};
    json["integrator"] = integratorName(scene.render.integrator);
    json["features"] = featuresJson(session.renderer().variant());
    json["counts"] = {{"shapes", countsJson(counts.shapes)},
                      {"lights", countsJson(counts.lights)},
                      {"materials", countsJson(counts.materials)}};
    json["kernel"] = kernelJson(session, options);
    json["accel"] = accelJson(session);
    json["parseSeconds"] = times.parse;
    json["setupSeconds"] = times.setup;
    json["firstFrameSeconds"] = times.firstFrame;
    json["cameraMoveSeconds"] = times.cameraMove;
    json["startup"] = startupJson(startupSplit(session, times));
    json["loopCap"] = {{"capped", cap.capped()}, {"budget", valueOrNull(cap.budget)}, {"description", cap.describe()}};
    json["loopPassesWorstCase"] = valueOrNull(staticLoopBound(scene));
    json["meshes"] =
        scene.meshes.empty() ? JsonObject(nullptr) : meshJson(meshFacts(scene, session.renderer().meshData()));
    json["textures"] = scene.textures ? texturesJson(*scene.textures, session.renderer().meshData().textures.chunking)
                                      : JsonObject(nullptr);
    return json;
}

int runInfo(const InfoOptions& options)
{
    // --json must not replace the scene, nor fail to be written after the work.
    checkOutputs({{"the scene file", options.scenePath}},
                 {jsonOutputFile(options.json), sceneJsonFile(options.sceneJson)});
    InfoTimes times;
    const auto parseStart = std::chrono::steady_clock::now();
    Scene scene = loadScene(options.scenePath);
    times.parse = secondsSince(parseStart);
    refuseOverlappingFiles(filesTheSceneRead(scene), {jsonOutputFile(options.json), sceneJsonFile(options.sceneJson)});
    if (!options.sceneJson.empty()) return writeSceneJson(scene, options.sceneJson);
    VulkanContext context({options.device, false});
    SessionConfig config;
    config.uber = options.uber;
    config.staged = options.staged;
    config.accel = options.accel;
    config.sceneReads = options.sceneReads;
    config.warmUp = false; // the first frame's time is what info measures
    config.maxTextureChunkBytes = options.maxTextureChunkBytes;
    // The variant info has always described: independent samples, no variance.
    config.sampler = SamplerChoice::Independent;
    auto start = std::chrono::steady_clock::now();
    RenderSession session(context, std::move(scene), config);
    times.setup = secondsSince(start);
    session.renderFrames(1);
    times.firstFrame = secondsSince(start);
    const auto moveStart = std::chrono::steady_clock::now();
    if (auto refused = session.moveCamera(session.scene().camera)) throw InternalError("camera move: " + *refused);
    times.cameraMove = secondsSince(moveStart);

    // With the JSON on standard output, the lines for people go to stderr.
    printInfo(options.json == "-" ? stderr : stdout, session, options, times);
    if (!options.json.empty()) writeJson(options.json, infoJson(session, options, times));
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
    cmd->add_flag("--staged", options->staged, "Describe the staged kernels (trace and shade) instead");
    addAccelOption(*cmd, options->accel);
    addSceneReadsOption(*cmd, options->sceneReads);
    cmd->add_option("--json", options->json,
                    "Also write these facts as one JSON object to FILE, or to standard output for - (the lines "
                    "above then go to stderr; docs/machine-output.md)");
    cmd->add_option("--scene-json", options->sceneJson,
                    "Write the scene as vkrt parsed it, as JSON, to FILE or to standard output for -, and stop "
                    "there: no device is needed (docs/scene-json.md)");
    addTextureChunkOption(*cmd, options->maxTextureChunkBytes);
    return [options] { return runInfo(*options); };
}

} // namespace vkrt
