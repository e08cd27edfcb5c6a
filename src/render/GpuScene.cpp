#include "render/GpuScene.h"

#include "material/MicrofacetAlbedo.h"
#include "material/Sheen.h"

#include "mesh/MeshGeometry.h"
#include "render/EmissionPower.h"
#include "render/LightTable.h"
#include "scene/FeatureSet.h"
#include "scene/SceneOverrides.h"
#include "scene/kinds/Kinds.h"
#include "shared/Bindings.h"

#include <chrono>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <type_traits>

namespace vkrt {

namespace {

glm::vec3 toFloat(const glm::dvec3& v) { return glm::vec3(v); }

/// GGX alphas from perceptual roughness (alpha = roughness^2) and anisotropy
/// (Burley 2012: aspect = sqrt(1 - 0.9 anisotropy), alphaX = alpha / aspect,
/// alphaY = alpha * aspect), never below MIN_GGX_ALPHA; roughness 0 keeps 0
/// (the smooth kinds), except for `pbr`, which has no smooth form: its GGX
/// lobe at alpha 0 divided by zero (a glTF mirror rendered black).
glm::vec2 ggxAlphas(const Material& m)
{
    if (m.roughness == 0.0 && m.type != MaterialType::Pbr) return glm::vec2(0.0f);
    const double alpha = m.roughness * m.roughness;
    const double aspect = std::sqrt(1.0 - 0.9 * m.anisotropy);
    const double minimum = gpu::MIN_GGX_ALPHA;
    return glm::vec2(float(std::max(alpha / aspect, minimum)), float(std::max(alpha * aspect, minimum)));
}

/// The mean of a material's diffuse colour, over its texture when it has one
/// (what Mitsuba's Texture::mean() gives for a bitmap).
double meanDiffuse(const Material& m, const TextureAtlas* textures)
{
    Color mean = m.diffuse;
    if (const auto& texture = m.texture(TextureSlot::Color)) {
        VKRT_CHECK(textures != nullptr);
        const auto texel = textures->meanOf(texture->record);
        mean *= Color(texel[0], texel[1], texel[2]);
    }
    return (mean.r + mean.g + mean.b) / 3.0;
}

/// Mitsuba's sampling weight of a plastic's coating: s / (s + d), with the
/// coating's reflectance s = 1 and d the mean of the diffuse colour.
float coatingLobeWeight(const Material& m, const TextureAtlas* textures)
{
    return float(1.0 / (1.0 + meanDiffuse(m, textures)));
}

gpu::MaterialTextures convertMaterialTextures(const Material& m)
{
    gpu::MaterialTextures g{};
    for (size_t slot = 0; slot < kTextureSlotCount; ++slot) {
        g.slots[slot] =
            gpu::TextureSlot{gpu::NO_TEXTURE, 0u, glm::vec2(1.0f), glm::vec2(0.0f), glm::vec2(1.0f, 0.0f), 0u};
        if (const auto& texture = m.textures[slot])
            g.slots[slot] = gpu::TextureSlot{texture->record,
                                             texture->channel,
                                             glm::vec2(texture->scale),
                                             glm::vec2(texture->offset),
                                             glm::vec2(std::cos(texture->rotation), std::sin(texture->rotation)),
                                             texture->texCoord};
    }
    g.normalStrength = float(m.normalStrength);
    g.clearcoatNormalStrength = float(m.clearcoatNormalStrength);
    return g;
}

/// The textures' buffers, never empty (the uber kernel binds them for any scene).
TextureBuffers packTextures(const Scene& scene, const TextureChunking& chunking)
{
    TextureBuffers buffers;
    if (scene.textures) buffers = scene.textures->pack(chunking);
    if (buffers.texels.empty()) buffers.texels.push_back(0u);
    if (buffers.records.empty()) buffers.records.push_back(gpu::TextureRecord{});
    return buffers;
}

gpu::Material convertMaterial(const Material& m, Integrator integrator, uint32_t tableStart, float internalReflectance,
                              const TextureAtlas* textures)
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
    if (m.type == MaterialType::RoughDielectric && m.fresnel == FresnelMode::Default) g.fresnel = gpu::FRESNEL_EXACT;
    const glm::vec2 alpha = ggxAlphas(m);
    g.alphaX = alpha.x;
    g.alphaY = alpha.y;
    g.eta = toFloat(m.eta);
    g.k = toFloat(m.k);
    g.metallic = float(m.metallic);
    g.table = tableStart;
    g.internalReflectance = internalReflectance;
    if (m.type == MaterialType::Plastic) g.lobeWeight = coatingLobeWeight(m, textures);
    if (m.type == MaterialType::Pbr) {
        g.specular = toFloat(m.layers.specularColor);
        g.specularFactor = float(m.layers.specular);
        g.sheenColor = toFloat(m.layers.sheenColor);
        g.sheenRoughness = float(m.layers.sheenRoughness);
        g.clearcoat = float(m.layers.clearcoat);
        g.clearcoatAlpha =
            float(std::max(m.layers.clearcoatRoughness * m.layers.clearcoatRoughness, double(gpu::MIN_GGX_ALPHA)));
        g.transmission = float(m.layers.transmission);
        g.pbrFlags = m.layers.volumetric() ? gpu::PBR_FLAG_VOLUME : 0u;
        if (!m.layers.volumetric()) g.absorption = glm::vec3(0.0f); // only a volume absorbs
        g.iridescence = float(m.layers.iridescence);
        g.iridescenceIor = float(m.layers.iridescenceIor);
        g.iridescenceThicknessMin = float(m.layers.iridescenceThicknessMin);
        g.iridescenceThickness = float(m.layers.iridescenceThicknessMax);
        // KHR_materials_anisotropy, in the tangent frame until a hit resolves it (lib/material_textures.glsl).
        const double strength = m.layers.anisotropy, rotation = m.layers.anisotropyRotation;
        g.anisotropy = glm::vec3(float(strength * std::cos(rotation)), float(strength * std::sin(rotation)), 0.0f);
    }
    return g;
}

/// Appends a rough plastic's coating table; returns where it starts.
uint32_t appendCoatingTable(const Material& m, std::vector<float>& tables)
{
    const auto start = uint32_t(tables.size());
    const auto table = roughTransmittanceTable(ggxAlphas(m).x, m.ior);
    static_assert(table.size() == gpu::MATERIAL_TABLE_SIZE);
    tables.insert(tables.end(), table.begin(), table.end());
    return start;
}

/// The plastics' coating data, once per scene (tens of milliseconds each).
static_assert(kSheenTableSide == gpu::SHEEN_TABLE_SIDE && float(kMinSheenAlpha) == gpu::MIN_SHEEN_ALPHA,
              "src/material/Sheen.h and shared/SceneTypes.h describe one sheen table");

void prepareMaterialTables(const Scene& scene, GpuSceneStatic& fixed)
{
    uint32_t sheenTable = gpu::NO_MATERIAL_TABLE; // one for every material with sheen
    for (const Material& m : scene.materials) {
        uint32_t start = gpu::NO_MATERIAL_TABLE;
        float internal = 0.0f;
        if (m.type == MaterialType::Pbr && m.layers.sheen()) {
            if (sheenTable == gpu::NO_MATERIAL_TABLE) {
                sheenTable = uint32_t(fixed.materialTables.size());
                const std::vector<float>& table = sheenAlbedoTable();
                fixed.materialTables.insert(fixed.materialTables.end(), table.begin(), table.end());
            }
            start = sheenTable;
        } else if (m.type == MaterialType::Plastic && m.roughness > 0.0) {
            start = appendCoatingTable(m, fixed.materialTables);
            internal = float(internalDiffuseReflectance(ggxAlphas(m).x, m.ior));
        } else if (m.type == MaterialType::Plastic) {
            internal = float(smoothInternalDiffuseReflectance(m.ior));
        }
        fixed.materialTableStart.push_back(start);
        fixed.internalReflectance.push_back(internal);
    }
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

// ------------------------------------------------------------------ meshes

glm::vec4 row(const glm::dmat4& m, int r) { return glm::vec4(glm::dvec4(m[0][r], m[1][r], m[2][r], m[3][r])); }

/// Object -> camera-relative world, composed in double: a mesh far from the
/// origin keeps full float precision near the camera.
glm::dmat4 toCameraRelative(const Mesh& mesh, const glm::dvec3& eye)
{
    glm::dmat4 m = mesh.objectToWorld;
    m[3] = glm::dvec4(glm::dvec3(m[3]) - eye, 1.0);
    return m;
}

double meanOf(const Color& c) { return (c.r + c.g + c.b) / 3.0; }

/// The material index of a mesh triangle (leaf slot).
uint32_t triangleMaterialIndex(const Mesh& mesh, uint32_t slot)
{
    if (mesh.fileMaterials.empty()) return mesh.material;
    return mesh.fileMaterials[mesh.geometry->data.triangleMaterials[slot]];
}

/// The scene material of a mesh triangle (leaf slot).
const Material& triangleMaterial(const Scene& scene, const Mesh& mesh, uint32_t slot)
{
    return scene.materials[triangleMaterialIndex(mesh, slot)];
}

/// A mesh triangle's emitted radiance: the mesh's own `emission`, else its material's.
Color triangleEmission(const Scene& scene, const Mesh& mesh, uint32_t slot)
{
    if (mesh.emission != Color(0.0)) return mesh.emission;
    return triangleMaterial(scene, mesh, slot).emission;
}

/// Whether a mesh triangle's emission is its material's, textured.
bool triangleEmissionTextured(const Scene& scene, const Mesh& mesh, uint32_t slot)
{
    return mesh.emission == Color(0.0) && emissionTextured(triangleMaterial(scene, mesh, slot));
}

/// A mesh triangle's texture coordinates of uv set `set` (zero without, as the kernel's MeshUvs).
std::array<glm::dvec2, 3> triangleUvs(const MeshGeometry& g, uint32_t slot, uint32_t set)
{
    const std::vector<glm::vec2>& uvs = set == 1 ? g.data.uvs1 : g.data.uvs;
    if (uvs.empty()) return {};
    const glm::uvec3 t = g.data.triangles[slot];
    return {glm::dvec2(uvs[t.x]), glm::dvec2(uvs[t.y]), glm::dvec2(uvs[t.z])};
}

/// The mean radiance a mesh triangle emits over its area: the emission,
/// times its emission texture's mean over the triangle where it has one.
double meanTriangleRadiance(const Scene& scene, const Mesh& mesh, uint32_t slot)
{
    const Color radiance = triangleEmission(scene, mesh, slot);
    if (!triangleEmissionTextured(scene, mesh, slot)) return meanOf(radiance);
    VKRT_CHECK(scene.textures != nullptr);
    const Material& m = triangleMaterial(scene, mesh, slot);
    const MaterialTexture& texture = *m.texture(TextureSlot::Emission);
    const glm::dvec3 texel =
        meanEmissionTexel(*scene.textures, texture, triangleUvs(*mesh.geometry, slot, texture.texCoord));
    return (radiance.r * texel.r + radiance.g * texel.g + radiance.b * texel.b) / 3.0;
}

std::array<glm::dvec3, 3> worldVertices(const Mesh& mesh, const MeshGeometry& g, uint32_t slot, const glm::dvec3& eye)
{
    const glm::dmat4 m = toCameraRelative(mesh, eye);
    const glm::uvec3 t = g.data.triangles[slot];
    std::array<glm::dvec3, 3> v;
    for (int k = 0; k < 3; ++k) v[k] = glm::dvec3(m * glm::dvec4(glm::dvec3(g.data.positions[t[k]]), 1.0));
    return v;
}

} // namespace

EmitterTable aliasTable(const std::vector<double>& power)
{
    EmitterTable table;
    const size_t n = power.size();
    table.pdf.resize(n);
    table.threshold.assign(n, 1.0f);
    table.alias.resize(n);
    for (double p : power) table.totalPower += p;
    if (n == 0 || !(table.totalPower > 0.0)) return table;
    std::vector<double> scaled(n);
    std::vector<uint32_t> small, large;
    for (size_t i = 0; i < n; ++i) {
        table.pdf[i] = power[i] / table.totalPower;
        scaled[i] = table.pdf[i] * double(n);
        table.alias[i] = uint32_t(i);
        (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
    }
    while (!small.empty() && !large.empty()) {
        const uint32_t s = small.back(), l = large.back();
        small.pop_back();
        table.threshold[s] = float(scaled[s]);
        table.alias[s] = l;
        scaled[l] -= 1.0 - scaled[s];
        if (scaled[l] < 1.0) {
            large.pop_back();
            small.push_back(l);
        }
    }
    // What remains is 1 up to rounding: always kept.
    for (uint32_t i : small) table.threshold[i] = 1.0f;
    for (uint32_t i : large) table.threshold[i] = 1.0f;
    return table;
}

namespace {

/// Every emitter's power, in emitter order: the triangle lights, then each
/// emissive mesh's triangles (a textured emission's power from the texture's
/// mean over the triangle: one over black texels only has power 0 and is
/// never chosen; hit by a BSDF-sampled ray, it keeps the full MIS weight).
EmitterTable emitterTableOf(const Scene& scene)
{
    std::vector<double> power;
    for (const TriangleLight& light : emittingTriangleLights(scene)) power.push_back(emittedPower(light));
    for (const Mesh& mesh : scene.meshes) {
        if (!meshEmits(scene, mesh)) continue;
        const MeshGeometry& g = *mesh.geometry;
        const double sides = mesh.twoSided ? 2.0 : 1.0;
        for (uint32_t slot = 0; slot < g.data.triangles.size(); ++slot) {
            const double area = triangleArea(worldVertices(mesh, g, slot, glm::dvec3(0.0)));
            const bool emits = area > 0.0 && float(area) > 0.0 && std::isfinite(area);
            const double radiance = emits ? meanTriangleRadiance(scene, mesh, slot) : 0.0;
            power.push_back(emits ? radiance * area * sides * glm::pi<double>() : 0.0);
        }
    }
    return aliasTable(power);
}

uint32_t topRef(int kind, size_t index)
{
    if (index > gpu::TOP_REF_MAX_INDEX)
        throw InputError("a scene may hold at most " + std::to_string(gpu::TOP_REF_MAX_INDEX + 1) +
                         " records of one kind");
    return (uint32_t(kind) << gpu::TOP_REF_INDEX_BITS) | uint32_t(index);
}

/// One kind's leaves of the top-level BVH: its bounds and TOP_REF, for a kind
/// with bounded = 1 in the registry; nothing for the others, which the kernel
/// tests in a loop.
template <bool Bounded, class Record>
void addTopLevelLeaves(const std::vector<Record>& records, int kind, std::vector<Aabb>& boxes,
                       std::vector<uint32_t>& refs)
{
    if constexpr (Bounded) {
        for (size_t i = 0; i < records.size(); ++i) {
            boxes.push_back(boundsOf(records[i]));
            refs.push_back(topRef(kind, i));
        }
    }
}

TopLevel buildTopLevel(const Scene& scene)
{
    std::vector<Aabb> boxes;
    std::vector<uint32_t> refs;
#define VKRT_ADD_LEAVES(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    addTopLevelLeaves<bounded != 0>(recordsToUpload(scene, scene.array), gpu::HIT_##Type, boxes, refs);
    VKRT_SHAPE_KINDS(VKRT_ADD_LEAVES)
    VKRT_LIGHT_KINDS(VKRT_ADD_LEAVES)
#undef VKRT_ADD_LEAVES
    TopLevel top;
    top.bvh = buildBvh(boxes, BvhOptions{.maxLeafSize = 2});
    for (uint32_t slot : top.bvh.order) {
        top.refs.push_back(refs[slot]);
        top.boxes.push_back(boxes[slot]);
    }
    return top;
}

template <bool Bounded, class Record>
void addRecordBoxes(const std::vector<Record>& records, int hitCode, const glm::dvec3& eye,
                    std::vector<RecordBoxes>& out)
{
    if constexpr (Bounded && !std::is_same_v<Record, Mesh>) {
        if (records.empty()) return;
        RecordBoxes kind;
        kind.hitCode = hitCode;
        for (const Record& record : records) {
            const Aabb world = boundsOf(record);
            glm::vec3 lower(std::numeric_limits<float>::quiet_NaN()), upper = lower;
            if (!world.empty()) {
                roundOutwards(Aabb{world.lower - eye, world.upper - eye}, lower, upper);
                // 2^-20 of the box's largest coordinate: far more than the
                // records' own rounding to float.
                float largest = 0.0f;
                for (int k = 0; k < 3; ++k) largest = std::max({largest, std::abs(lower[k]), std::abs(upper[k])});
                const float margin = std::ldexp(largest, -20);
                lower -= margin;
                upper += margin;
            }
            kind.lower.push_back(lower);
            kind.upper.push_back(upper);
        }
        out.push_back(std::move(kind));
    }
}

} // namespace

std::vector<RecordBoxes> recordBoxes(const Scene& scene)
{
    std::vector<RecordBoxes> kinds;
#define VKRT_ADD_RECORD_BOXES(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    addRecordBoxes<bounded != 0>(recordsToUpload(scene, scene.array), gpu::HIT_##Type, scene.camera.eye, kinds);
    VKRT_SHAPE_KINDS(VKRT_ADD_RECORD_BOXES)
    VKRT_LIGHT_KINDS(VKRT_ADD_RECORD_BOXES)
#undef VKRT_ADD_RECORD_BOXES
    return kinds;
}

namespace {

/// The top-level nodes with camera-relative boxes, from the leaves up
/// (children always follow their parent in the array).
std::vector<gpu::BvhNode> refitTopLevel(const TopLevel& top, const glm::dvec3& eye)
{
    std::vector<Aabb> nodeBoxes(top.bvh.nodes.size());
    for (size_t i = top.bvh.nodes.size(); i-- > 0;) {
        const gpu::BvhNode& node = top.bvh.nodes[i];
        Aabb box;
        if (node.count > 0) {
            for (uint32_t k = 0; k < node.count; ++k) {
                const Aabb& leaf = top.boxes[node.first + k];
                if (!leaf.empty()) box.extend(Aabb{leaf.lower - eye, leaf.upper - eye});
            }
        } else {
            box.extend(nodeBoxes[node.first]);
            box.extend(nodeBoxes[node.first + 1]);
        }
        nodeBoxes[i] = box;
    }
    std::vector<gpu::BvhNode> nodes = top.bvh.nodes;
    for (size_t i = 0; i < nodes.size(); ++i) {
        // An empty box becomes a point at +infinity, which no ray enters (accel/Bvh.h).
        roundOutwards(nodeBoxes[i], nodes[i].lower, nodes[i].upper);
    }
    return nodes;
}

void checkBufferSize(uint64_t bytes, uint64_t maxBytes, const std::string& what, const Scene& scene)
{
    if (bytes <= maxBytes) return;
    // Name the geometry that contributes most, the one to decimate.
    const MeshGeometry* biggest = nullptr;
    for (const Mesh& m : scene.meshes)
        if (!biggest || m.geometry->gpuBytes() > biggest->gpuBytes()) biggest = m.geometry.get();
    throw InputError(scene.path + ": the scene's " + what + " need " + std::to_string(bytes >> 20) +
                     " MiB, more than the device's maxStorageBufferRange of " + std::to_string(maxBytes >> 20) +
                     " MiB" +
                     (biggest ? " (the largest mesh is " + biggest->file.string() + ", " +
                                    std::to_string(biggest->data.triangles.size()) + " triangles)"
                              : std::string()) +
                     "; use fewer or smaller meshes");
}

/// An emitter with its alias-table entry (choice probability, threshold, alias).
gpu::Emitter withAliasEntry(gpu::Emitter e, const EmitterTable& table, uint32_t index)
{
    e.pdf = float(table.pdf[index]);
    e.aliasThreshold = table.threshold[index];
    e.alias = table.alias[index];
    return e;
}

/// One kind's GPU records, in upload order (toGpu: scene/kinds/).
template <class Record, class GpuRecord>
void appendGpuRecords(const std::vector<Record>& records, const Relativizer& rel, std::vector<GpuRecord>& out)
{
    for (size_t i = 0; i < records.size(); ++i) out.push_back(toGpu(records[i], rel, uint32_t(i)));
}

/// Mesh instances need the geometry pool: convertMeshes makes their records.
void appendGpuRecords(const std::vector<Mesh>&, const Relativizer&, std::vector<gpu::Mesh>&) {}

/// The triangle lights' emitters, the first of all (toGpu gives each light its index).
void convertTriangleLightEmitters(const Scene& scene, const GpuSceneStatic& fixed, GpuSceneData& data)
{
    const Relativizer rel{scene.camera.eye};
    for (const TriangleLight& light : emittingTriangleLights(scene)) {
        const auto index = uint32_t(data.emitters.size());
        data.emitters.push_back(withAliasEntry(emitterOf(light, rel), fixed.emitters, index));
    }
}

/// Mesh instances, with their emitters after those of the triangle lights.
void convertMeshes(const Scene& scene, const GpuSceneStatic& fixed, const glm::dvec3& eye, GpuSceneData& data)
{
    auto firstEmitter = uint32_t(data.emitters.size());
    for (const Mesh& mesh : scene.meshes) {
        const MeshGeometry& g = *mesh.geometry;
        const GeometryOffsets& at = fixed.offsets.at(&g);
        const glm::dmat4 toWorld = toCameraRelative(mesh, eye);
        const glm::dmat4 toObject = glm::inverse(toWorld);
        gpu::Mesh record{};
        record.toWorld0 = row(toWorld, 0);
        record.toWorld1 = row(toWorld, 1);
        record.toWorld2 = row(toWorld, 2);
        record.toObject0 = row(toObject, 0);
        record.toObject1 = row(toObject, 1);
        record.toObject2 = row(toObject, 2);
        record.emission = toFloat(mesh.emission);
        record.material = mesh.material;
        record.root = at.root;
        record.firstTriangle = at.firstTriangle;
        record.firstNormals = at.firstNormals;
        const bool emissive = meshEmits(scene, mesh);
        record.flags = (at.normals ? gpu::MESH_FLAG_NORMALS : 0u) | (emissive ? gpu::MESH_FLAG_EMISSIVE : 0u) |
                       (mesh.twoSided ? gpu::MESH_FLAG_TWO_SIDED : 0u) |
                       (!g.data.uvs.empty() ? gpu::MESH_FLAG_UVS : 0u) |
                       (!g.data.uvs1.empty() ? gpu::MESH_FLAG_UVS1 : 0u) |
                       (!g.data.tangents.empty() ? gpu::MESH_FLAG_TANGENTS : 0u) |
                       (!mesh.fileMaterials.empty() ? gpu::MESH_FLAG_MATERIALS : 0u) |
                       (meshHasVertexColors(mesh) ? gpu::MESH_FLAG_COLORS : 0u) |
                       (meshAlphaTested(scene, mesh) ? gpu::MESH_FLAG_ALPHA : 0u);
        record.firstEmitter = firstEmitter;
        data.meshes.push_back(record);
        if (!emissive) continue;
        for (uint32_t slot = 0; slot < g.data.triangles.size(); ++slot, ++firstEmitter) {
            const auto v = worldVertices(mesh, g, slot, eye);
            gpu::Emitter e{};
            e.v0 = toFloat(v[0]);
            e.v1 = toFloat(v[1]);
            e.v2 = toFloat(v[2]);
            e.area = float(triangleArea(v));
            e.twoSided = mesh.twoSided ? 1u : 0u;
            e.radiance = toFloat(triangleEmission(scene, mesh, slot));
            e.textures = triangleEmissionTextured(scene, mesh, slot) ? triangleMaterialIndex(mesh, slot)
                                                                     : gpu::NO_EMISSION_TEXTURE;
            e.uvs = at.firstTriangle + slot;
            data.emitters.push_back(withAliasEntry(e, fixed.emitters, firstEmitter));
        }
    }
}

void convertCamera(const Camera& camera, gpu::SceneUniforms& u)
{
    // Scaled before normalising (SceneOverrides' normalized): an up of
    // (0, 1e-300, 0), valid, made glm::normalize divide by a length that underflows to 0.
    glm::dvec3 forward = *normalized(difference(camera.eye, camera.target));
    glm::dvec3 right = *normalized(glm::cross(forward, *normalized(camera.up)));
    glm::dvec3 up = glm::cross(right, forward);
    // Perspective: scaled to the plane one unit ahead; orthographic: the view's half extents.
    double halfHeight =
        camera.orthographic() ? camera.orthographicHeight / 2.0 : std::tan(glm::radians(camera.fovY) / 2.0);
    double halfWidth = halfHeight * double(camera.width) / double(camera.height);
    u.cameraRight = toFloat(right * halfWidth);
    u.cameraUp = toFloat(up * halfHeight);
    u.cameraForward = toFloat(forward);
    u.width = camera.width;
    u.height = camera.height;
    u.apertureRadius = float(camera.apertureRadius);
    u.focusDistance = float(camera.resolvedFocusDistance());
}

} // namespace

std::vector<TriangleLight> emittingTriangleLights(const Scene& scene)
{
    std::vector<TriangleLight> lights;
    for (const auto& l : scene.triangleLights)
        if (emits(l)) lights.push_back(l);
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

/// The dielectric (and volumetric pbr) objects the eye is inside (spheres, boxes, the back side of
/// planes), outermost first, at most MEDIUM_STACK_DEPTH of the innermost.
/// Decided in double on the world coordinates. Nesting order comes from the
/// distance between the eye and each boundary: for A inside B, the eye is
/// never farther from A's boundary than from B's (the segment to B's nearest
/// point crosses A's boundary). Of identical (coincident) objects only the
/// first counts, as the kernel only ever meets the first of them.
std::vector<uint32_t> mediaAroundCamera(const Scene& scene)
{
    std::vector<std::pair<double, uint32_t>> around; // (distance to the boundary, material)
    // A volumetric pbr material bounds a medium as the dielectrics do (lib/media.glsl).
    auto dielectric = [&](uint32_t m) {
        const Material& material = scene.materials[m];
        return material.type == MaterialType::Dielectric || material.type == MaterialType::RoughDielectric ||
               (material.type == MaterialType::Pbr && material.layers.volumetric());
    };
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

uint64_t meshTriangleCount(const Scene& scene)
{
    uint64_t total = 0;
    for (const Mesh& m : scene.meshes) total += m.geometry->data.triangles.size();
    return total;
}

uint64_t emissiveTriangleCount(const Scene& scene)
{
    uint64_t total = 0;
    for (const Mesh& m : scene.meshes)
        if (meshEmits(scene, m)) total += m.geometry->data.triangles.size();
    return total;
}

/// One geometry's per-triangle texture coordinates, tangents and materials
/// (in leaf order, beside its MeshTriangles), for the features that need them.
void appendTriangleAttributes(const Mesh& mesh, const FeatureSet& features, GpuSceneStatic& fixed)
{
    const MeshData& d = mesh.geometry->data;
    auto appendUvs = [&](const std::vector<glm::vec2>& uvs, std::vector<gpu::MeshUvs>& to) {
        for (const glm::uvec3& t : d.triangles)
            to.push_back(uvs.empty() ? gpu::MeshUvs{} : gpu::MeshUvs{uvs[t.x], uvs[t.y], uvs[t.z]});
    };
    if (features.textures) appendUvs(d.uvs, fixed.meshUvs);
    if (features.textures && features.secondUvs) appendUvs(d.uvs1, fixed.meshUvs1);
    if (features.tangentFrames()) {
        for (const glm::uvec3& t : d.triangles) {
            fixed.meshTangents.push_back(d.tangents.empty()
                                             ? gpu::MeshTangents{}
                                             : gpu::MeshTangents{d.tangents[t.x], d.tangents[t.y], d.tangents[t.z]});
        }
    }
    if (features.vertexColors) {
        const glm::vec4 white(1.0f);
        for (const glm::uvec3& t : d.triangles)
            fixed.meshColors.push_back(d.colors.empty() ? gpu::MeshColors{white, white, white}
                                                        : gpu::MeshColors{d.colors[t.x], d.colors[t.y], d.colors[t.z]});
    }
    if (features.fileMaterials) {
        for (uint32_t slot = 0; slot < d.triangles.size(); ++slot)
            fixed.meshMaterials.push_back(mesh.fileMaterials.empty() ? mesh.material
                                                                     : mesh.fileMaterials[d.triangleMaterials[slot]]);
    }
}

GpuSceneStatic prepareStaticScene(const Scene& scene, uint64_t maxBytes, const TextureChunking& textureChunking)
{
    GpuSceneStatic fixed;
    prepareMaterialTables(scene, fixed);
    for (const Material& m : scene.materials) fixed.materialTextures.push_back(convertMaterialTextures(m));
    if (fixed.materialTextures.empty()) fixed.materialTextures.push_back(gpu::MaterialTextures{});
    for (const Material& m : scene.materials)
        fixed.materialAlpha.push_back(gpu::MaterialAlpha{uint32_t(m.alphaMode), float(m.alphaCutoff), float(m.alpha)});
    if (fixed.materialAlpha.empty()) fixed.materialAlpha.push_back(gpu::MaterialAlpha{});
    fixed.textures = packTextures(scene, textureChunking);
    fixed.emitters = emitterTableOf(scene);
    checkBufferSize(fixed.emitters.pdf.size() * sizeof(gpu::Emitter), maxBytes, "emitters", scene);
    if (scene.meshes.empty()) return fixed;
    const FeatureSet features = featuresOf(scene);
    // The per-triangle attributes start at index 0 beside meshTriangles: drop the placeholders.
    if (features.textures) fixed.meshUvs.clear();
    if (features.textures && features.secondUvs) fixed.meshUvs1.clear();
    if (features.tangentFrames()) fixed.meshTangents.clear();
    if (features.fileMaterials) fixed.meshMaterials.clear();
    if (features.vertexColors) fixed.meshColors.clear();
    for (const Mesh& mesh : scene.meshes) {
        const MeshGeometry& g = *mesh.geometry;
        if (fixed.offsets.count(&g)) continue;
        appendTriangleAttributes(mesh, features, fixed);
        GeometryOffsets at{uint32_t(fixed.meshNodes.size()), uint32_t(fixed.meshTriangles.size()),
                           uint32_t(fixed.meshNormals.size()), !g.data.normals.empty()};
        fixed.offsets[&g] = at;
        fixed.meshNodes.insert(fixed.meshNodes.end(), g.bvh.nodes.begin(), g.bvh.nodes.end());
        const auto& p = g.data.positions;
        for (const glm::uvec3& t : g.data.triangles) fixed.meshTriangles.push_back({p[t.x], p[t.y], p[t.z]});
        if (at.normals) {
            const auto& n = g.data.normals;
            for (const glm::uvec3& t : g.data.triangles) fixed.meshNormals.push_back({n[t.x], n[t.y], n[t.z]});
        }
    }
    checkBufferSize(fixed.meshNodes.size() * sizeof(gpu::BvhNode), maxBytes, "BVH nodes", scene);
    checkBufferSize(fixed.meshTriangles.size() * sizeof(gpu::MeshTriangle), maxBytes, "mesh triangles", scene);
    checkBufferSize(fixed.meshNormals.size() * sizeof(gpu::MeshNormals), maxBytes, "mesh normals", scene);
    checkBufferSize(fixed.meshUvs.size() * sizeof(gpu::MeshUvs), maxBytes, "mesh texture coordinates", scene);
    checkBufferSize(fixed.meshUvs1.size() * sizeof(gpu::MeshUvs), maxBytes, "mesh texture coordinates (TEXCOORD_1)",
                    scene);
    checkBufferSize(fixed.meshTangents.size() * sizeof(gpu::MeshTangents), maxBytes, "mesh tangents", scene);
    checkBufferSize(fixed.meshColors.size() * sizeof(gpu::MeshColors), maxBytes, "mesh vertex colours", scene);
    if (fixed.meshUvs.empty()) fixed.meshUvs.push_back(gpu::MeshUvs{});
    if (fixed.meshUvs1.empty()) fixed.meshUvs1.push_back(gpu::MeshUvs{});
    if (fixed.meshTangents.empty()) fixed.meshTangents.push_back(gpu::MeshTangents{});
    if (fixed.meshMaterials.empty()) fixed.meshMaterials.push_back(0u);
    if (fixed.meshColors.empty()) fixed.meshColors.push_back(gpu::MeshColors{});
    const auto start = std::chrono::steady_clock::now();
    fixed.top = buildTopLevel(scene);
    fixed.topBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return fixed;
}

GpuSceneData convertScene(const Scene& scene, const FrameSettings& settings, const GpuSceneStatic& fixed)
{
    GpuSceneData data;
    Relativizer rel{scene.camera.eye};
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        data.materials.push_back(convertMaterial(scene.materials[i], scene.render.integrator,
                                                 fixed.materialTableStart.at(i), fixed.internalReflectance.at(i),
                                                 scene.textures.get()));
    }
#define VKRT_CONVERT_RECORDS(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    appendGpuRecords(recordsToUpload(scene, scene.array), rel, data.array);
    VKRT_SHAPE_KINDS(VKRT_CONVERT_RECORDS)
    VKRT_LIGHT_KINDS(VKRT_CONVERT_RECORDS)
#undef VKRT_CONVERT_RECORDS
    convertTriangleLightEmitters(scene, fixed, data);
    convertMeshes(scene, fixed, scene.camera.eye, data);
    // Soft suns first: the only ones an escaped ray can find (lib/lights/directional.glsl).
    const auto firstDelta =
        std::stable_partition(data.directionalLights.begin(), data.directionalLights.end(),
                              [](const gpu::DirectionalLight& light) { return light.oneMinusCos > 0.0f; });
    data.uniforms.softDirectionalLightCount = uint32_t(firstDelta - data.directionalLights.begin());
    if (usesLightTable(scene)) buildLightTable(scene, fixed, data);
    if (fixed.top) {
        data.topNodes = refitTopLevel(*fixed.top, scene.camera.eye);
        data.topRefs = fixed.top->refs;
    }

    gpu::SceneUniforms& u = data.uniforms;
    convertCamera(scene.camera, u);
    u.flags = (settings.jitter ? gpu::RENDER_FLAG_JITTER : 0u) |
              (scene.camera.orthographic() ? gpu::RENDER_FLAG_ORTHOGRAPHIC : 0u);
    u.backgroundColor = toFloat(scene.background.color);
    if (scene.background.environment) {
        const glm::dmat3& rotation = scene.background.environment->rotation;
        u.environmentAxisX = toFloat(rotation[0]);
        u.environmentAxisY = toFloat(rotation[1]);
        u.environmentAxisZ = toFloat(rotation[2]);
    }
    u.maxDepth = uint32_t(scene.render.maxDepth);
#define VKRT_COUNT_RECORDS(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    u.field##Count = uint32_t(data.array.size());
    VKRT_SHAPE_KINDS(VKRT_COUNT_RECORDS)
    VKRT_LIGHT_KINDS(VKRT_COUNT_RECORDS)
#undef VKRT_COUNT_RECORDS
    // Each band's dispatch walks its own tiles (kernels/render.comp); every
    // band is as tall as the first, the last one's extra rows outside the image.
    u.tileCount = tileCountFor(u.width, settings.bandRows > 0 ? std::min(settings.bandRows, u.height) : u.height);
    u.tileStride = tileStrideFor(u.tileCount);
    std::vector<uint32_t> media = mediaAroundCamera(scene);
    u.cameraMediumCount = uint32_t(media.size());
    for (size_t i = 0; i < media.size(); ++i) u.cameraMedia[int(i)] = media[i];
    u.emitterCount = uint32_t(data.emitters.size());
    u.topNodeCount = uint32_t(data.topNodes.size());
    return data;
}

} // namespace vkrt
