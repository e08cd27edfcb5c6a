// Mesh instances (`shape = "mesh"`): keys, reader (the file loaded once per
// (file, normals) through the parse's cache, the transform, file materials)
// and world bounds. Its GPU record needs the scene's geometry pool, so
// render/GpuScene.cpp makes it (convertMeshes); the kernel's side is
// shaders/lib/shapes/mesh.glsl.
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"
#include "scene/FileMaterialImport.h"
#include "scene/MaterialUse.h"
#include "scene/SceneOverrides.h"
#include "scene/SceneValues.h"
#include "scene/kinds/Kinds.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <optional>

namespace vkrt {

KeyList meshKeys()
{
    static constexpr std::array<std::string_view, 11> keys{"shape",
                                                           "material",
                                                           "file",
                                                           "scale",
                                                           "rotate",
                                                           "translate",
                                                           "matrix",
                                                           "normals",
                                                           "emission",
                                                           "two_sided",
                                                           "allow_outside_references"};
    return keys;
}

namespace {

namespace fs = std::filesystem;

std::vector<uint32_t> fileMaterialsOf(const MeshGeometry& geometry, const Field& materialField, ParseContext& context)
{
    Scene& scene = context.scene;
    const auto known = context.fileMaterials.find(&geometry);
    if (known != context.fileMaterials.end()) return known->second;
    std::vector<uint32_t> indices;
    try {
        indices =
            importFileMaterials(geometry, materialField.location(), context.textures, scene.materials, scene.warnings);
    } catch (const SceneError&) {
        throw;
    } catch (const InputError& error) {
        materialField.fail(error.what());
    }
    context.fileMaterials.emplace(&geometry, indices);
    return indices;
}

/// `scale`: one number or three, none zero (a negative one mirrors).
glm::dvec3 readScale(const Field& field)
{
    glm::dvec3 scale = field.node().is_array() ? readVector(field) : glm::dvec3(readNumber(field));
    for (int axis = 0; axis < 3; ++axis)
        if (scale[axis] == 0.0) field.fail("must not be zero (it would flatten the mesh)");
    return scale;
}

/// `matrix`: four rows of four numbers, an invertible affine transform.
glm::dmat4 readMatrix(const Field& field)
{
    const toml::array* rows = field.node().as_array();
    if (!rows || rows->size() != 4)
        field.fail("expected 4 rows of 4 numbers, got " +
                   (rows ? std::to_string(rows->size()) + " row(s)" : describeType(field.node())));
    glm::dmat4 m(1.0);
    for (size_t r = 0; r < 4; ++r) {
        const Field row = field.element(r, *rows->get(r));
        const toml::array* values = row.node().as_array();
        if (!values || values->size() != 4)
            row.fail("expected a row of 4 numbers, got " +
                     (values ? std::to_string(values->size()) + " element(s)" : describeType(row.node())));
        for (size_t c = 0; c < 4; ++c) m[int(c)][int(r)] = readNumber(row.element(c, *values->get(c)));
    }
    if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
        field.fail("the last row must be [0, 0, 0, 1] (an affine transform)");
    const double det = glm::determinant(glm::dmat3(m));
    if (!(std::abs(det) > 0.0) || !std::isfinite(det)) field.fail("is singular (its 3x3 part has determinant 0)");
    const glm::dmat4 inverse = glm::inverse(m);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(inverse[c][r])) field.fail("cannot be inverted in double precision");
    return m;
}

glm::dmat4 readObjectToWorld(const TableField& table)
{
    if (const auto matrix = table.find("matrix")) {
        for (std::string_view key : {"scale", "rotate", "translate"})
            if (const auto other = table.find(key))
                other->fail("cannot be combined with matrix (line " + std::to_string(matrix->location().line) +
                            "); give the whole transform as the matrix, or use scale, rotate and translate");
        return readMatrix(*matrix);
    }
    const glm::dvec3 scale = readOr(table, "scale", glm::dvec3(1.0), readScale);
    const glm::dmat4 rotation = readOr(table, "rotate", glm::dmat4(1.0), readRotation);
    const glm::dvec3 translation = readOr(table, "translate", glm::dvec3(0.0), readVector);
    return glm::translate(glm::dmat4(1.0), translation) * rotation * glm::scale(glm::dmat4(1.0), scale);
}

constexpr std::array<EnumName<NormalMode>, 3> normalModes{
    {{"file", NormalMode::File}, {"smooth", NormalMode::Smooth}, {"face", NormalMode::Face}}};

std::filesystem::path readMeshPath(const Field& field)
{
    const fs::path path = readPath(field);
    const std::string extension = lowercase(path.extension().string());
    const auto& supported = supportedMeshExtensions();
    if (std::find(supported.begin(), supported.end(), extension) == supported.end()) {
        std::vector<std::string_view> names(supported.begin(), supported.end());
        field.fail("unsupported mesh file " + quote(path.string()) + " (supported: " + joinList(names) + ")");
    }
    checkRegularFile(field, path);
    return path;
}

/// Every material a mesh instance uses.
std::vector<uint32_t> materialsOf(const Mesh& mesh)
{
    return mesh.fileMaterials.empty() ? std::vector<uint32_t>{mesh.material} : mesh.fileMaterials;
}

/// Textures need the file's texture coordinates; an emissive material needs no `emission` of the mesh's own.
void checkMeshMaterials(const Mesh& mesh, const Field& materialField, const Scene& scene)
{
    for (uint32_t index : materialsOf(mesh))
        if (auto problem = meshMaterialProblem(mesh, scene.materials[index])) materialField.fail(*problem);
}

} // namespace

void readMesh(const TableField& table, uint32_t material, ParseContext& context)
{
    Scene& scene = context.scene;
    Mesh mesh;
    mesh.material = material;
    mesh.where = table.field().location();
    const Field fileField = table.require("file");
    const fs::path file = readMeshPath(fileField);
    const NormalMode normals = readOr(table, "normals", NormalMode::File, [](const Field& field) {
        return readChoice(field, "normals mode", normalModes).value;
    });
    // The scene is the user's own, so it may trust a mesh file's references outside its folder.
    MeshLoadOptions loadOptions;
    loadOptions.allowOutsideReferences = readOr(table, "allow_outside_references", false, readBool);
    mesh.objectToWorld = readObjectToWorld(table);
    mesh.emission = readOr(table, "emission", Color(0.0), readRadiance);
    if (const auto twoSided = table.find("two_sided")) {
        if (!table.find("emission")) twoSided->fail("only applies to an emissive mesh (one with `emission`)");
        mesh.twoSided = readBool(*twoSided);
    }
    try {
        mesh.geometry = context.meshes.get(file, normals, loadOptions);
    } catch (const SceneError&) {
        throw;
    } catch (const InputError& error) {
        fileField.fail(std::string("cannot load the mesh: ") + error.what());
    }
    const Field materialField = table.require("material");
    if (material == kFileMaterialIndex) {
        mesh.fileMaterials = fileMaterialsOf(*mesh.geometry, materialField, context);
        mesh.material = mesh.fileMaterials.front();
    }
    checkMeshMaterials(mesh, materialField, scene);
    scene.meshes.push_back(std::move(mesh));
}

Aabb boundsOf(const Mesh& mesh)
{
    Aabb box;
    const Aabb& b = mesh.geometry->bounds;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p((corner & 1) ? b.upper.x : b.lower.x, (corner & 2) ? b.upper.y : b.lower.y,
                           (corner & 4) ? b.upper.z : b.lower.z);
        box.extend(glm::dvec3(mesh.objectToWorld * glm::dvec4(p, 1.0)));
    }
    // The transform itself rounds: widen by a few ulps of the box's size.
    const glm::dvec3 margin = (glm::abs(box.lower) + glm::abs(box.upper)) * 1e-12;
    box.lower -= margin;
    box.upper += margin;
    return box;
}

} // namespace vkrt
