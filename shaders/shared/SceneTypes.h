// GPU scene records. Layout rule: GLSL `scalar` block layout
// (GL_EXT_scalar_block_layout), which matches C++'s natural layout of these
// structs; the host static_asserts every size (src/gpu/SharedTypes.cpp) and a
// test compares every offset with glslang's reflection.
// Positions are camera-relative (the eye is the origin), computed in double
// on the host, so precision does not depend on where the scene sits in space.
#ifndef VKRT_SHARED_SCENE_TYPES_H
#define VKRT_SHARED_SCENE_TYPES_H
#include "Interop.h"
#include "Bindings.h"
#include "Kinds.h"

VKRT_BEGIN_NAMESPACE

// Material::type is a MATERIAL_* kind of shared/Kinds.h.

// Material::fresnel
VKRT_CONSTANT(uint, FRESNEL_NONE, 0)
VKRT_CONSTANT(uint, FRESNEL_SCHLICK, 1)
VKRT_CONSTANT(uint, FRESNEL_EXACT, 2)

// Material::table of a plastic without a table (a smooth coating)
VKRT_CONSTANT(uint, NO_MATERIAL_TABLE, 4294967295u)
// A rough plastic's table in materialTables (shared/Bindings.h): the rough
// coating's transmittance 1 - R(mu) at mu = i / (MATERIAL_TABLE_SIZE - 1),
// i = 0 ... MATERIAL_TABLE_SIZE - 1 (src/material/MicrofacetAlbedo.h).
VKRT_CONSTANT(uint, MATERIAL_TABLE_SIZE, 64)
// The sheen albedo table (pbr materials with sheen share one, its start in
// their Material::table): E(mu, r), the directional albedo of the Charlie
// sheen BRDF (KHR_materials_sheen) of roughness r at cosine mu, at
// r = j / (SHEEN_TABLE_SIDE - 1) and mu = s^2, s = i / (SHEEN_TABLE_SIDE - 1)
// (E turns sharply near grazing: in sqrt(mu) bilinear lookups stay within
// 1e-3 of it), entry j * SHEEN_TABLE_SIDE + i (src/material/Sheen.h).
VKRT_CONSTANT(uint, SHEEN_TABLE_SIDE, 64)
// The narrowest sheen: alpha_g = roughness^2 kept at or above this (the
// Charlie distribution divides by it).
VKRT_CONSTANT(float, MIN_SHEEN_ALPHA, 1e-3)

// Which members a kind reads (the rest are zero):
//   lambert: diffuse; phong: diffuse, specular, exponent;
//   mirror, glossy: specular, exponent (glossy), ior, fresnel;
//   dielectric: ior, absorption, fresnel;
//   conductor: specular (tint), alphaX, alphaY, eta, k;
//   rough_dielectric: ior, absorption, fresnel, alphaX = alphaY;
//   plastic: diffuse, ior, alphaX = alphaY (0: smooth), table, lobeWeight, internalReflectance;
//   pbr: diffuse (base colour), metallic, alphaX = alphaY; with the glTF
//        extension layers (variants with VKRT_PBR_LAYERS) also specular
//        (KHR_materials_specular's colour), specularFactor, ior, sheenColor,
//        sheenRoughness, clearcoat, clearcoatAlpha, table (the sheen table),
//        transmission, pbrFlags, absorption (inside a volumetric one) and the
//        iridescence members.
// alpha is the GGX width (perceptual roughness squared), never below
// MIN_GGX_ALPHA where it is used.
struct Material {
    vec3 diffuse;
    uint type;
    vec3 specular;
    float exponent;
    vec3 absorption;
    float ior;
    uint fresnel;
    float alphaX;
    float alphaY;
    uint table;
    vec3 eta;
    float metallic;
    vec3 k;
    float lobeWeight;          // plastic: Mitsuba's specular sampling weight s / (s + d)
    float internalReflectance; // plastic: diffuse Fresnel reflectance inside the coating
    vec3 sheenColor;           // pbr: KHR_materials_sheen's colour (0: no sheen)
    float sheenRoughness;      // pbr: its roughness (alpha_g = roughness^2)
    float specularFactor;      // pbr: KHR_materials_specular's strength (dielectric F90; scales F0)
    float clearcoat;           // pbr: KHR_materials_clearcoat's factor (0: no coat)
    float clearcoatAlpha;      // pbr: the coat's GGX alpha, clearcoatRoughness^2 (>= MIN_GGX_ALPHA)
    float transmission;   // pbr: KHR_materials_transmission's factor (0: opaque; variants with VKRT_PBR_TRANSMISSION)
    uint pbrFlags;        // pbr: PBR_FLAG_* below
    float iridescence;    // pbr: KHR_materials_iridescence's factor (0: none; variants with VKRT_PBR_IRIDESCENCE)
    float iridescenceIor; // pbr: the thin film's index
    float iridescenceThicknessMin; // pbr: the film's thickness in nm where its thickness texture reads 0
    float iridescenceThickness;    // pbr: ... where it reads 1, and the thickness without a texture
    // pbr: KHR_materials_anisotropy (variants with VKRT_PBR_ANISOTROPY). In the
    // buffer: strength x (cos, sin) of its rotation, in the surface's tangent
    // frame (z 0). texturedMaterial resolves it at a hit: then it is the world
    // direction of the stretched GGX axis (unit), alphaX the stretched alpha,
    // or zero where the lobe is isotropic.
    vec3 anisotropy;
    // pbr: the clear coat's shading normal at a hit (world; texturedMaterial
    // sets it from clearcoatNormalTexture, or keeps the normal a base normal
    // map tilts); zero: the coat shares the base's shading normal.
    vec3 clearcoatNormal;
};

// Material::pbrFlags
// A transmitting pbr material whose mesh bounds a volume (KHR_materials_volume
// of thickness > 0): transmitted light refracts by `ior` into a medium that
// absorbs by `absorption`, as a rough dielectric's does. Without the flag
// transmission is thin-walled: light passes unrefracted (the reflection lobe
// mirrored through the surface) and enters no medium.
VKRT_CONSTANT(uint, PBR_FLAG_VOLUME, 1)

// The narrowest GGX lobe a rough material gets: narrower ones lose float
// precision in D and the visible-normal sampler (roughness 0 selects the
// smooth kinds instead).
VKRT_CONSTANT(float, MIN_GGX_ALPHA, 1e-4)

struct Sphere {
    vec3 center;
    float radius;
    uint material;
};

struct Box {
    vec3 lower;
    uint material;
    vec3 upper;
};

struct Triangle {
    vec3 v0;
    uint material;
    vec3 v1;
    vec3 v2;
};

struct Plane {
    vec3 point;
    uint material;
    vec3 normal;
};

// Mesh::flags
VKRT_CONSTANT(uint, MESH_FLAG_NORMALS, 1)    // meshNormals holds shading normals for its triangles
VKRT_CONSTANT(uint, MESH_FLAG_EMISSIVE, 2)   // its triangles are emitters firstEmitter, ...
VKRT_CONSTANT(uint, MESH_FLAG_TWO_SIDED, 4)  // they emit on both sides
VKRT_CONSTANT(uint, MESH_FLAG_UVS, 8)        // meshUvs holds its triangles' texture coordinates
VKRT_CONSTANT(uint, MESH_FLAG_TANGENTS, 16)  // meshTangents holds its triangles' tangents
VKRT_CONSTANT(uint, MESH_FLAG_MATERIALS, 32) // meshMaterials holds each triangle's material (file materials)
VKRT_CONSTANT(uint, MESH_FLAG_COLORS, 64)    // meshColors holds its triangles' vertex colours (glTF COLOR_0)
VKRT_CONSTANT(uint, MESH_FLAG_ALPHA, 128)    // some material of it is alpha-tested (MaterialAlpha: MASK or BLEND)
VKRT_CONSTANT(uint, MESH_FLAG_UVS1, 256)     // meshUvs1 holds its triangles' second texture coordinates

/// One instance of a mesh (src/scene/Scene.h: Mesh). The matrices are the
/// object -> camera-relative world transform and its inverse, as three rows
/// of a 3x4 matrix each, composed in double on the host.
struct Mesh {
    vec4 toWorld0;
    vec4 toWorld1;
    vec4 toWorld2;
    vec4 toObject0;
    vec4 toObject1;
    vec4 toObject2;
    vec3 emission;
    uint material;
    uint root;          // its geometry's root node in meshNodes
    uint firstTriangle; // its geometry's first MeshTriangle in meshTriangles
    uint firstNormals;  // its geometry's first MeshNormals in meshNormals (MESH_FLAG_NORMALS)
    uint flags;
    uint firstEmitter; // its first triangle's Emitter (MESH_FLAG_EMISSIVE)
};

/// Shading normals at a mesh triangle's three vertices (object space; a zero
/// normal means "use the face normal").
struct MeshNormals {
    vec3 n0;
    vec3 n1;
    vec3 n2;
};

// MaterialAlpha::mode: glTF 2.0's alphaMode.
VKRT_CONSTANT(uint, ALPHA_MODE_OPAQUE, 0) // always a surface
VKRT_CONSTANT(uint, ALPHA_MODE_MASK, 1)   // a surface where alpha >= cutoff, else rays pass through
VKRT_CONSTANT(uint, ALPHA_MODE_BLEND, 2)  // a surface with probability alpha (stochastic transparency)

/// A material's coverage (one per Material, same index; variants with
/// VKRT_HAS_ALPHA only, lib/alpha.glsl): alpha = `alpha` (glTF
/// baseColorFactor.a) times the A channel of the material's colour texture
/// (TEXTURE_SLOT_COLOR of its MaterialTextures), tested at every candidate
/// hit on a mesh triangle, for every kind of ray.
struct MaterialAlpha {
    uint mode;
    float cutoff; // MASK
    float alpha;
};

/// Texture coordinates at a mesh triangle's three vertices, stored beside its
/// MeshTriangle (same index: firstTriangle + leaf slot).
struct MeshUvs {
    vec2 uv0;
    vec2 uv1;
    vec2 uv2;
};

/// Linear RGBA vertex colours at a mesh triangle's three vertices (glTF
/// COLOR_0, multiplying the base colour of its file material). Same index as MeshUvs.
struct MeshColors {
    vec4 c0;
    vec4 c1;
    vec4 c2;
};

/// Tangents at a mesh triangle's three vertices (object space): xyz along
/// increasing u, w = +-1 with bitangent = w cross(normal, tangent). Same index
/// as MeshUvs.
struct MeshTangents {
    vec4 t0;
    vec4 t1;
    vec4 t2;
};

/// One emitting triangle, camera-relative world space: the triangle lights
/// first (TriangleLight::emitter), then every emissive mesh triangle
/// (Mesh::firstEmitter). Emitters are chosen in proportion to power with
/// Walker's alias method: pick slot i uniformly, keep it if u <
/// aliasThreshold, else take `alias`; `pdf` is the probability of choosing
/// this triangle. An emissive mesh triangle whose material has an emission
/// texture (VKRT_HAS_EMISSION_TEXTURES) names that material in `textures`
/// (its MaterialTextures, slot TEXTURE_SLOT_EMISSION) and its texture
/// coordinates in `uvs` (a MeshUvs index, firstTriangle + leaf slot): the
/// texel at the point's uv multiplies `radiance`, and `pdf` is in proportion
/// to the texture's mean over the triangle (src/render/EmissionPower.h).
/// Otherwise `textures` is NO_EMISSION_TEXTURE.
VKRT_CONSTANT(uint, NO_EMISSION_TEXTURE, 4294967295u)

struct Emitter {
    vec3 v0;
    float area;
    vec3 v1;
    uint twoSided;
    vec3 v2;
    float pdf;
    vec3 radiance;
    float aliasThreshold;
    uint alias;
    uint textures;
    uint uvs;
};

struct PointLight {
    vec3 position;
    vec3 intensity;
};

/// A directional light (a sun): from every point the same direction,
/// `toLight`, or (oneMinusCos > 0) a cone of directions around it of half
/// angle alpha, oneMinusCos = 1 - cos(alpha) and sin2Alpha = sin^2(alpha),
/// both from double on the host (float loses a small cone's 1 - cos). A
/// delta light's `radiance` is its irradiance (W/m^2 facing it); a cone's is
/// the uniform radiance that gives that irradiance, E / (pi sin^2 alpha).
struct DirectionalLight {
    vec3 toLight;
    float oneMinusCos;
    vec3 radiance;
    float sin2Alpha;
};

/// A spot light: a point light whose intensity (W/sr on the axis) falls off
/// as glTF's KHR_lights_punctual says: t = clamp((cos a - cosOuter) *
/// falloffScale, 0, 1) squared, a the angle from `axis`, falloffScale =
/// 1 / (cos inner - cos outer); falloffScale = 0 for inner == outer (a hard
/// edge: 1 inside the cone, 0 outside).
struct SpotLight {
    vec3 position;
    float cosOuter;
    vec3 intensity;
    float falloffScale;
    vec3 axis;
};

/// One entry of the light table, read only by variants with
/// VKRT_LIGHT_TABLE (scenes with more point, spot and directional lights than
/// the kernel tests one by one: src/render/LightTable.h). The entries are the
/// table's lights of each light kind in registry order, one per record (none
/// for triangle lights), then one entry for all emitters together when the
/// scene has some. Chosen in proportion to power with Walker's alias method
/// as emitters are; `pdf` is the probability of choosing the entry.
struct LightPick {
    float pdf;
    float aliasThreshold;
    uint alias;
};

/// A triangle light's geometry, camera-relative world space: what rays are
/// tested against. What it emits is emitters[emitter] (Emitter), in the one
/// alias table of every emitting triangle.
struct TriangleLight {
    vec3 v0;
    uint emitter;
    vec3 v1;
    vec3 v2;
};

/// One node of a bounding volume hierarchy (src/accel/Bvh.h). Inner node
/// (count == 0): children `first` and `first + 1`, relative to the tree's
/// root. Leaf (count > 0): primitives first ... first + count - 1 of the
/// tree's primitive list.
struct BvhNode {
    vec3 lower;
    uint first;
    vec3 upper;
    uint count;
};

/// One mesh triangle's object-space vertices, stored in its mesh's BVH leaf
/// order so that a leaf's triangles are contiguous (no index indirection).
struct MeshTriangle {
    vec3 v0;
    vec3 v1;
    vec3 v2;
};

// Top-level BVH leaves reference records as TOP_REF(kind, index): the
// kind's HIT_Type code (shared/Kinds.h) in the top 8 bits, the record's
// index in the low 24.
VKRT_CONSTANT(uint, TOP_REF_INDEX_BITS, 24)
VKRT_CONSTANT(uint, TOP_REF_MAX_INDEX, 16777215)

// SceneUniforms::flags
VKRT_CONSTANT(uint, RENDER_FLAG_JITTER, 1)
// The camera projects orthographically (kernels with VKRT_ORTHOGRAPHIC, lib/camera.glsl).
VKRT_CONSTANT(uint, RENDER_FLAG_ORTHOGRAPHIC, 2)
// The environment's texels are all equal (render/EnvironmentSampling.h): its
// light samples follow the cosine lobe about the shading normal instead of
// the map's distribution (lib/lights.glsl: constantEnvironmentPdf).
VKRT_CONSTANT(uint, RENDER_FLAG_CONSTANT_ENVIRONMENT, 4)

/// Per-render constants. Camera ray for pixel coordinate (x, y) in [0,w]x[0,h]:
/// normalize(ndc.x * cameraRight + ndc.y * cameraUp + cameraForward).
// Scene arrays live in uniform buffers when every one fits (lavapipe reads
// uniform buffers markedly faster than storage buffers; shared/NUMERICS.md).
// Each array then has this many records, 16 KiB being the smallest
// maxUniformBufferRange Vulkan allows; src/gpu/SharedTypes.cpp checks the
// sizes. Bigger scenes use the storage-buffer variant. The shape and light
// arrays' capacities (UNIFORM_SPHERES, ...) are in the registry, shared/Kinds.h.
VKRT_CONSTANT(uint, UNIFORM_MATERIALS, 93) // 16384 / 176

// One record count per shape and light array, in registry order:
// sphereCount, boxCount, triangleCount, planeCount, pointLightCount, ...
#define VKRT_COUNT_MEMBER(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) uint field##Count;

struct SceneUniforms {
    vec3 cameraRight; // scaled by tan(fov/2) * aspect
    uint width;
    vec3 cameraUp; // scaled by tan(fov/2)
    uint height;
    vec3 cameraForward;
    uint flags;
    vec3 backgroundColor;
    uint maxDepth;
    VKRT_SHAPE_KINDS(VKRT_COUNT_MEMBER)
    VKRT_LIGHT_KINDS(VKRT_COUNT_MEMBER)
    uint tileCount;          // workgroup tiles in the image
    uint tileStride;         // coprime to tileCount: scatters tiles over the image
    uint environmentSize;    // cubemap face width N (0 without a cubemap)
    uint cameraMediumCount;  // dielectrics containing the eye (lib/media.glsl)
    uvec4 cameraMedia;       // their materials, innermost last
    uint emitterCount;       // Emitter records (triangle lights, then emissive mesh triangles)
    uint topNodeCount;       // nodes of the top-level BVH (0: none; the kernel loops over the arrays)
    float apertureRadius;    // thin lens (VKRT_THIN_LENS): the lens's radius, scene units
    float focusDistance;     // ... and the plane in focus's distance along cameraForward
    uvec2 environmentExtent; // lat-long map (VKRT_HAS_LATLONG): width W, height H in texels
    uvec2 environmentGrid;   // its sampling grid: columns, rows (render/EnvironmentSampling.h)
    uint environmentBlock;   // bilinear cells a side per grid cell
    // The map -> world rotation's columns: world = x * axisX + y * axisY + z * axisZ.
    vec3 environmentAxisX;
    vec3 environmentAxisY;
    vec3 environmentAxisZ;
    // Directional lights whose cone is wider than a point (oneMinusCos > 0):
    // the first this many records, the only ones a ray that escapes can find.
    uint softDirectionalLightCount;
    // The light table (VKRT_LIGHT_TABLE): its entries (LightPick), and the
    // candidates drawn from it at each shading point, of which one gets the
    // shadow ray (lib/lights.glsl).
    uint lightTableCount;
    uint lightCandidates;
    // Each read-only scene buffer's device address, low word first, at its
    // binding (lib/scene_buffers.glsl; 0 where the variant has no such buffer).
    uvec2 bufferAddresses[ADDRESSED_BINDING_COUNT];
};

/// Per-batch values (push constants), pushed once per submission: lavapipe
/// re-specializes a kernel whenever push constants change (about 3 ms per
/// dispatch), so each frame of a batch gets its index from the dispatch's
/// base workgroup z instead: frame = firstFrame + gl_WorkGroupID.z. Used only
/// as hash inputs, never in control flow.
struct FrameConstants {
    uint firstFrame;
    uint seed;
};

/// The frames a run of dispatches adds (a storage buffer written before each
/// run): dispatch z adds, to every pixel, frames firstFrame + z * S up to
/// min(firstFrame + (z + 1) * S, frameEnd), S = framesPerInvocation, one
/// invocation per pixel running them back to back (render.comp: a lane whose
/// path ends starts its next sample at once). A storage buffer and not push
/// constants or uniforms, because lavapipe inlines those where they steer
/// control flow and compiles the kernel again for every new value.
struct FrameRun {
    uint framesPerInvocation;
    uint frameEnd;
};

/// One pixel's running sum: Kahan-compensated, over `count` accepted samples.
struct AccumPixel {
    vec3 sum;
    uint count;
    vec3 compensation;
};

/// One pixel's running variance (Welford): mean and the sum of squared
/// deviations m2 over the same accepted samples as AccumPixel; m2 is
/// Kahan-compensated so it stays accurate over millions of samples.
struct MomentPixel {
    vec3 mean;
    vec3 m2;
    vec3 m2Compensation;
};

/// One pixel's arbitrary output values (`vkrt render --aov`): running means
/// over the pixel's accepted samples (AccumPixel::count) of the albedo and
/// world-space shading normal of each sample's first non-specular surface
/// (through perfect mirrors and glass; zero where the path escapes or ends
/// first), and over the `hits` samples whose camera ray found a surface of
/// that first hit's camera-space depth (along the viewing direction) and
/// camera-relative position.
struct AovPixel {
    vec3 albedo;
    vec3 normal;
    vec3 position;
    float depth;
    uint hits;
};

/// Counters written by kernels with atomics.
struct RenderStats {
    uint maxLoopIterations; // largest loop count of one sample seen
    uint budgetExceeded;    // invocations that would have crossed LOOP_BUDGET
};

VKRT_END_NAMESPACE

#endif
