#include "mesh/MeshLoader.h"

#include "mesh/FileMaterials.h"
#include "mesh/GltfReader.h"
#include "mesh/PlyReader.h"
#include "mesh/ReferencePolicy.h"

#include "util/Error.h"
#include "util/Hash.h"

#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unordered_map>

namespace fs = std::filesystem;

// Debian's assimp is built with its internal assertions on (ASSIMP_BUILD_DEBUG),
// and their handler aborts the process: malformed input that trips one (the
// fuzzer found a PLY that fails TriangulateProcess's face count) would crash
// vkrt. This definition replaces the library's (the executable exports it,
// CMakeLists.txt: --export-dynamic-symbol) and throws instead; importScene
// turns the exception into an error that names the file.
namespace Assimp {
__attribute__((visibility("default"))) void aiAssertViolation(const char* expression, const char* file, int line)
{
    throw std::runtime_error("the Open Asset Import Library's internal check failed (" + std::string(expression) +
                             ", " + std::string(file) + ":" + std::to_string(line) +
                             "); the file is malformed in a way it does not report");
}
} // namespace Assimp

namespace vkrt {
namespace {

// ---------------------------------------------------------------------------
// Messages: every error starts with the file (and the line where known).

[[noreturn]] void fail(const fs::path& file, const std::string& message, int line = 0)
{
    throw InputError(file.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message);
}

std::string lowerExtension(const fs::path& file)
{
    std::string extension = file.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return extension;
}

/// The format assimp reads for vkrt (PLY and glTF have readers of their own).
std::string formatName(const std::string&) { return "OBJ"; }

std::string describe(const glm::vec3& v)
{
    std::ostringstream text;
    text << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return text.str();
}

std::string readText(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// ---------------------------------------------------------------------------
// OBJ line finding. Assimp's OBJ errors carry no line number and its output
// has one vertex per face corner, so the file's own vertex number is lost.
// These scans only locate a problem assimp (or our validation) already found;
// they never decide what the mesh is.

/// Calls visit(lineNumber, keyword, rest) for each line; stops when it returns true.
template <typename Visit>
std::optional<int> findObjLine(std::string_view text, Visit visit)
{
    int lineNumber = 0;
    while (!text.empty()) {
        const size_t end = std::min(text.find('\n'), text.size());
        std::string_view line = text.substr(0, end);
        text.remove_prefix(std::min(end + 1, text.size()));
        ++lineNumber;
        const size_t start = line.find_first_not_of(" \t");
        if (start == std::string_view::npos) continue;
        line.remove_prefix(start);
        const size_t keywordEnd = std::min(line.find_first_of(" \t\r"), line.size());
        if (visit(lineNumber, line.substr(0, keywordEnd), line.substr(keywordEnd))) return lineNumber;
    }
    return std::nullopt;
}

std::vector<std::string> tokens(std::string_view rest)
{
    std::vector<std::string> result;
    std::istringstream in{std::string(rest)};
    for (std::string token; in >> token;) result.push_back(token);
    return result;
}

/// The line of the first `v` line with a NaN or infinite coordinate, and that vertex's 1-based number.
std::optional<std::pair<int, int>> findObjNonFiniteVertex(std::string_view text)
{
    int vertexNumber = 0;
    const std::optional<int> line = findObjLine(text, [&](int, std::string_view keyword, std::string_view rest) {
        if (keyword != "v") return false;
        ++vertexNumber;
        const std::vector<std::string> coordinates = tokens(rest);
        for (size_t i = 0; i < coordinates.size() && i < 3; ++i) {
            if (!std::isfinite(std::strtod(coordinates[i].c_str(), nullptr))) return true;
        }
        return false;
    });
    if (!line) return std::nullopt;
    return std::make_pair(*line, vertexNumber);
}

/// The first f/l/p line with an index of 0 or beyond the file's v/vt/vn lines (negative: relative to those so far).
std::optional<int> findObjBadIndex(std::string_view text)
{
    std::array<long, 3> totals{}; // v, vt, vn
    findObjLine(text, [&](int, std::string_view keyword, std::string_view) {
        if (keyword == "v") ++totals[0];
        if (keyword == "vt") ++totals[1];
        if (keyword == "vn") ++totals[2];
        return false;
    });
    std::array<long, 3> sofar{};
    auto badCorner = [&](const std::string& corner) {
        size_t start = 0;
        for (size_t kind = 0; kind < 3 && start <= corner.size(); ++kind) {
            const size_t end = std::min(corner.find('/', start), corner.size());
            long index = 0;
            const auto [rest, error] = std::from_chars(corner.data() + start, corner.data() + end, index);
            if (end > start && (error != std::errc() || rest != corner.data() + end)) return true; // not a number
            if (end > start && (index == 0 || index > totals[kind] || index < -sofar[kind])) return true;
            start = end + 1;
        }
        return false;
    };
    return findObjLine(text, [&](int, std::string_view keyword, std::string_view rest) {
        if (keyword == "v") ++sofar[0];
        if (keyword == "vt") ++sofar[1];
        if (keyword == "vn") ++sofar[2];
        if (keyword != "f" && keyword != "l" && keyword != "p") return false;
        const std::vector<std::string> corners = tokens(rest);
        return std::any_of(corners.begin(), corners.end(), badCorner);
    });
}

// ---------------------------------------------------------------------------
// Before assimp: clear messages for what is not a mesh file at all.

void checkIsMeshFile(const fs::path& file)
{
    std::error_code error;
    const fs::file_status status = fs::status(file, error);
    if (!fs::exists(status)) fail(file, "no such file");
    if (fs::is_directory(status)) fail(file, "is a directory, not a mesh file");
    if (!fs::is_regular_file(status)) fail(file, "is not a regular file");
    const std::string extension = lowerExtension(file);
    const std::vector<std::string>& supported = supportedMeshExtensions();
    if (std::find(supported.begin(), supported.end(), extension) == supported.end()) {
        std::string list;
        for (const std::string& each : supported) list += (list.empty() ? "" : ", ") + each;
        fail(file, "unsupported mesh file extension '" + extension + "' (supported: " + list + ")");
    }
    if (fs::file_size(file, error) == 0 && !error) fail(file, "empty file");
}

// ---------------------------------------------------------------------------
// Assimp import.

constexpr unsigned kImportSteps = aiProcess_ValidateDataStructure   // first: out-of-range indices, broken buffers
                                  | aiProcess_Triangulate           // polygons -> triangles
                                  | aiProcess_SortByPType           // one primitive type per mesh
                                  | aiProcess_PreTransformVertices; // one flat list

[[noreturn]] void failImport(const fs::path& file, const std::string& extension, const std::string& reason)
{
    std::optional<int> line;
    if (extension == ".obj" && reason.find("index") != std::string::npos) line = findObjBadIndex(readText(file));
    fail(file, "cannot read the " + formatName(extension) + " file: " + reason, line.value_or(0));
}

/// The OBJ line `mtllib` line naming `library`, or 0.
int mtllibLine(const fs::path& file, const std::string& library)
{
    const std::optional<int> line =
        findObjLine(readText(file), [&](int, std::string_view keyword, std::string_view rest) {
            return keyword == "mtllib" && rest.find(library) != std::string_view::npos;
        });
    return line.value_or(0);
}

/// A file the mesh references that the policy refused, or that could not be
/// opened, is the error, whether or not assimp went on without it: assimp
/// skips a missing .mtl silently, or fails with a bare "File read error".
void checkReferences(const fs::path& file, const std::string& extension, const ReferencePolicy& policy,
                     const ReferenceLog& log)
{
    const bool obj = extension == ".obj";
    const char* what = obj ? "the material library" : "the referenced file";
    if (log.refused) {
        const std::string uri = policy.uriOf(*log.refused);
        policy.check(*log.refused, uri, obj ? "its mtllib line" : "", obj ? mtllibLine(file, uri) : 0);
    }
    if (log.missing) {
        const std::string uri = policy.uriOf(*log.missing);
        fail(file, std::string(what) + " '" + uri + "' cannot be read: " + *log.missing + ": " + log.missingReason,
             obj ? mtllibLine(file, uri) : 0);
    }
}

const aiScene* importScene(Assimp::Importer& importer, const fs::path& file, const std::string& extension,
                           const ReferencePolicy& policy, std::vector<fs::path>& opened)
{
    // Points and lines are dropped by SortByPType; an all-lines file then has no meshes, reported below.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    ReferenceLog log;
    importer.SetIOHandler(newConfinedIoSystem(policy, log)); // the importer owns it
    const aiScene* scene = nullptr;
    try {
        // No logger is ever created, so assimp writes nothing to stdout/stderr (its default is a null logger).
        scene = importer.ReadFile(file.string(), kImportSteps);
    } catch (const std::exception& error) {
        checkReferences(file, extension, policy, log);
        failImport(file, extension, error.what());
    }
    checkReferences(file, extension, policy, log);
    opened = log.opened;
    if (scene) return scene;
    const std::string reason = importer.GetErrorString();
    if (reason.find("No meshes remaining") != std::string::npos ||
        reason.find("mNumMeshes is 0") != std::string::npos) {
        fail(file, "no triangles in " + file.string() + " (it has only points or lines, or is no mesh file at all)");
    }
    if (reason.find("No suitable reader") != std::string::npos) {
        fail(file,
             "is not a " + formatName(extension) + " file: the Open Asset Import Library recognises no format in it");
    }
    failImport(file, extension, reason);
}

// ---------------------------------------------------------------------------
// aiScene -> MeshData, checking every value.

struct MeshCheck {
    const fs::path& file;
    std::string extension;
    size_t meshCount = 0;

    std::string where(size_t mesh, size_t vertex) const
    {
        return (meshCount > 1 ? "mesh " + std::to_string(mesh) + ", " : "") + "vertex " + std::to_string(vertex) +
               " (counting from 0)";
    }

    [[noreturn]] void nonFinitePosition(size_t mesh, size_t vertex, const glm::vec3& value) const
    {
        if (extension == ".obj") {
            if (const auto found = findObjNonFiniteVertex(readText(file))) {
                fail(file, "vertex " + std::to_string(found->second) + " has a non-finite coordinate", found->first);
            }
        }
        fail(file, where(mesh, vertex) + " has a non-finite coordinate " + describe(value));
    }
};

glm::vec3 toGlm(const aiVector3D& v) { return {v.x, v.y, v.z}; }

bool allFinite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::vector<const aiMesh*> triangleMeshes(const aiScene& scene)
{
    std::vector<const aiMesh*> meshes;
    for (unsigned i = 0; i < scene.mNumMeshes; ++i) {
        const aiMesh* mesh = scene.mMeshes[i];
        if (mesh && (mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) && mesh->mNumFaces > 0) meshes.push_back(mesh);
    }
    return meshes;
}

/// A file normal made unit length; zero-length ones become (0, 0, 0), "use the face normal".
glm::vec3 unitNormal(const MeshCheck& check, size_t mesh, size_t vertex, const aiVector3D& normal)
{
    const glm::vec3 n = toGlm(normal);
    if (!allFinite(n)) fail(check.file, check.where(mesh, vertex) + " has a non-finite normal " + describe(n));
    const float length = glm::length(n);
    return length > 0.0f && std::isfinite(length) ? n / length : glm::vec3(0.0f);
}

/// A file tangent (assimp: tangent and bitangent) as MeshData keeps it: unit,
/// w from the side of cross(normal, tangent) the bitangent is on.
glm::vec4 fileTangent(const MeshCheck& check, size_t mesh, size_t vertex, const glm::vec3& normal,
                      const aiVector3D& tangent, const aiVector3D& bitangent)
{
    const glm::vec3 t = toGlm(tangent), b = toGlm(bitangent);
    if (!allFinite(t) || !allFinite(b))
        fail(check.file, check.where(mesh, vertex) + " has a non-finite tangent " + describe(t));
    const float length = glm::length(t);
    if (!(length > 0.0f) || !std::isfinite(length)) {
        // No direction to keep: the tangent of last resort (MeshData.h).
        return glm::vec4(normal == glm::vec3(0.0f) ? glm::vec3(1.0f, 0.0f, 0.0f) : perpendicularTo(normal), 1.0f);
    }
    const float side = glm::dot(glm::cross(normal, t), b) < 0.0f ? -1.0f : 1.0f;
    return glm::vec4(t / length, side);
}

struct VertexAttributes {
    bool normals = false, uvs = false, tangents = false;
};

void appendVertices(MeshData& out, const aiMesh& mesh, size_t meshIndex, const MeshCheck& check,
                    VertexAttributes attributes)
{
    const auto [normals, uvs, tangents] = attributes;
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
        const glm::vec3 position = toGlm(mesh.mVertices[v]);
        if (!allFinite(position)) check.nonFinitePosition(meshIndex, v, position);
        out.positions.push_back(position);
        if (normals) out.normals.push_back(unitNormal(check, meshIndex, v, mesh.mNormals[v]));
        if (tangents) {
            out.tangents.push_back(
                fileTangent(check, meshIndex, v, out.normals.back(), mesh.mTangents[v], mesh.mBitangents[v]));
        }
        if (uvs) {
            const glm::vec2 uv(mesh.mTextureCoords[0][v].x, mesh.mTextureCoords[0][v].y);
            if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
                fail(check.file, check.where(meshIndex, v) + " has a non-finite texture coordinate");
            }
            out.uvs.push_back(uv);
        }
    }
}

void appendTriangles(MeshData& out, const aiMesh& mesh, uint32_t base, const MeshCheck& check)
{
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const aiFace& face = mesh.mFaces[f];
        if (face.mNumIndices != 3) continue; // points/lines left in a mixed mesh
        glm::uvec3 triangle;
        for (int corner = 0; corner < 3; ++corner) {
            if (face.mIndices[corner] >= mesh.mNumVertices) {
                fail(check.file, "triangle " + std::to_string(f) + " uses vertex " +
                                     std::to_string(face.mIndices[corner]) + " of only " +
                                     std::to_string(mesh.mNumVertices));
            }
            triangle[corner] = base + face.mIndices[corner];
        }
        out.triangles.push_back(triangle);
    }
}

MeshData convertScene(const aiScene& scene, const MeshCheck& baseCheck)
{
    const std::vector<const aiMesh*> meshes = triangleMeshes(scene);
    MeshCheck check = baseCheck;
    check.meshCount = meshes.size();
    // Attributes only where every sub-mesh has them: a partial set would need a per-vertex "absent" marker.
    const auto every = [&](auto has) { return std::all_of(meshes.begin(), meshes.end(), has); };
    VertexAttributes attributes;
    attributes.normals = every([](const aiMesh* m) { return m->HasNormals(); });
    attributes.uvs = every([](const aiMesh* m) { return m->HasTextureCoords(0); });
    // Tangents belong to uvs and are oriented by normals.
    attributes.tangents =
        attributes.normals && attributes.uvs && every([](const aiMesh* m) { return m->HasTangentsAndBitangents(); });
    MeshData out;
    for (size_t i = 0; i < meshes.size(); ++i) {
        if (out.positions.size() + meshes[i]->mNumVertices > std::numeric_limits<uint32_t>::max()) {
            fail(check.file, "more than 2^32 vertices");
        }
        const auto base = static_cast<uint32_t>(out.positions.size());
        appendVertices(out, *meshes[i], i, check, attributes);
        appendTriangles(out, *meshes[i], base, check);
    }
    if (out.triangles.empty()) fail(check.file, "no triangles in " + check.file.string());
    return out;
}

// ---------------------------------------------------------------------------
// OBJ: assimp gives each face corner its own vertex. Joining corners whose
// position, normal and uv are bit-for-bit equal restores the file's
// v/vt/vn sharing, so that smooth normals (shared by index) are smooth.

struct CornerKey {
    std::array<uint32_t, 8> bits{};
    bool operator==(const CornerKey&) const = default;
};

struct CornerKeyHash {
    size_t operator()(const CornerKey& key) const
    {
        return Fnv1a64().add({reinterpret_cast<const char*>(key.bits.data()), sizeof key.bits}).value();
    }
};

CornerKey cornerKey(const MeshData& mesh, uint32_t vertex)
{
    std::array<float, 8> values{};
    std::memcpy(values.data(), &mesh.positions[vertex], sizeof(glm::vec3));
    if (!mesh.normals.empty()) std::memcpy(values.data() + 3, &mesh.normals[vertex], sizeof(glm::vec3));
    if (!mesh.uvs.empty()) std::memcpy(values.data() + 6, &mesh.uvs[vertex], sizeof(glm::vec2));
    CornerKey key;
    std::memcpy(key.bits.data(), values.data(), sizeof values);
    return key;
}

void joinIdenticalCorners(MeshData& mesh)
{
    std::unordered_map<CornerKey, uint32_t, CornerKeyHash> firstUse;
    std::vector<uint32_t> remap(mesh.positions.size());
    MeshData joined;
    for (uint32_t vertex = 0; vertex < mesh.positions.size(); ++vertex) {
        const auto [entry, inserted] = firstUse.try_emplace(cornerKey(mesh, vertex), joined.positions.size());
        remap[vertex] = entry->second;
        if (!inserted) continue;
        joined.positions.push_back(mesh.positions[vertex]);
        if (!mesh.normals.empty()) joined.normals.push_back(mesh.normals[vertex]);
        if (!mesh.uvs.empty()) joined.uvs.push_back(mesh.uvs[vertex]);
        if (!mesh.tangents.empty()) joined.tangents.push_back(mesh.tangents[vertex]);
    }
    joined.triangles = std::move(mesh.triangles);
    joined.triangleMaterials = std::move(mesh.triangleMaterials);
    joined.materials = std::move(mesh.materials);
    for (glm::uvec3& triangle : joined.triangles) triangle = {remap[triangle.x], remap[triangle.y], remap[triangle.z]};
    mesh = std::move(joined);
}

} // namespace

const std::vector<std::string>& supportedMeshExtensions()
{
    static const std::vector<std::string> extensions{".obj", ".ply", ".gltf", ".glb"};
    return extensions;
}

MeshData loadMeshFile(const fs::path& file, const MeshLoadOptions& options)
{
    checkIsMeshFile(file);
    const std::string extension = lowerExtension(file);
    if (extension == ".ply") return readPlyFile(file); // not assimp: see PlyReader.h
    if (extension == ".gltf" || extension == ".glb") {
        GltfReadOptions gltf;
        gltf.references = options;
        return flattenGltfModel(readGltfModel(file, gltf)); // not assimp: see GltfReader.h
    }
    const ReferencePolicy policy(file, options);
    Assimp::Importer importer;
    std::vector<fs::path> opened;
    const aiScene* scene = importScene(importer, file, extension, policy, opened);
    MeshData mesh = convertScene(*scene, MeshCheck{file, extension});
    if (extension == ".obj") joinIdenticalCorners(mesh);
    mesh.referencedFiles = std::move(opened);
    return mesh;
}

} // namespace vkrt
