#include "mesh/PlyReader.h"

#include "util/Error.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace fs = std::filesystem;

namespace vkrt {
namespace {

// Real headers are a few hundred bytes; one that is still going after this
// many is not a PLY header.
constexpr size_t kMaxHeaderBytes = 1 << 20;

[[noreturn]] void fail(const fs::path& file, int line, const std::string& message)
{
    throw InputError(file.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message);
}

std::vector<std::string_view> words(std::string_view line)
{
    std::vector<std::string_view> out;
    size_t at = 0;
    while (at < line.size()) {
        while (at < line.size() && (line[at] == ' ' || line[at] == '\t' || line[at] == '\r')) ++at;
        size_t end = at;
        while (end < line.size() && line[end] != ' ' && line[end] != '\t' && line[end] != '\r') ++end;
        if (end > at) out.push_back(line.substr(at, end - at));
        at = end;
    }
    return out;
}

// ---------------------------------------------------------------------------
// Header

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<Scalar> scalarType(std::string_view type)
{
    if (type == "char" || type == "int8") return Scalar::Int8;
    if (type == "uchar" || type == "uint8") return Scalar::UInt8;
    if (type == "short" || type == "int16") return Scalar::Int16;
    if (type == "ushort" || type == "uint16") return Scalar::UInt16;
    if (type == "int" || type == "int32") return Scalar::Int32;
    if (type == "uint" || type == "uint32") return Scalar::UInt32;
    if (type == "float" || type == "float32") return Scalar::Float32;
    if (type == "double" || type == "float64") return Scalar::Float64;
    return std::nullopt;
}

uint64_t scalarBytes(Scalar type)
{
    switch (type) {
    case Scalar::Int8:
    case Scalar::UInt8: return 1;
    case Scalar::Int16:
    case Scalar::UInt16: return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32: return 4;
    case Scalar::Float64: return 8;
    }
    return 0;
}

bool isInteger(Scalar type) { return type != Scalar::Float32 && type != Scalar::Float64; }

struct Property {
    std::string name;
    Scalar type = Scalar::Float32;   ///< of the value, or of a list's entries
    std::optional<Scalar> countType; ///< set for a list
};

struct Element {
    std::string name;
    uint64_t count = 0;
    int line = 0;
    std::vector<Property> properties;

    /// Bytes one binary instance takes at least: its scalars and list counts.
    uint64_t minBinaryBytes() const
    {
        uint64_t bytes = 0;
        for (const Property& p : properties) bytes += scalarBytes(p.countType.value_or(p.type));
        return bytes;
    }
};

enum class Format { Ascii, LittleEndian, BigEndian };

struct Header {
    Format format = Format::Ascii;
    std::vector<Element> elements;
    size_t bytes = 0; ///< up to and including the end_header line
    int lines = 0;
};

class HeaderReader {
public:
    HeaderReader(const fs::path& file, const std::string& text) : m_file(file), m_text(text) {}

    Header read()
    {
        Header header;
        if (nextLine() != "ply") fail(m_file, 1, "not a PLY file: the first line is not 'ply'");
        bool sawFormat = false;
        for (;;) {
            const std::optional<std::string_view> line = nextLine();
            if (!line) {
                fail(m_file, m_line,
                     "the PLY header has no 'end_header' line" +
                         std::string(m_text.size() >= kMaxHeaderBytes ? " in its first MiB" : ""));
            }
            const std::vector<std::string_view> w = words(*line);
            if (w.empty()) continue;
            if (w[0] == "end_header") break;
            if (w[0] == "comment" || w[0] == "obj_info") continue;
            if (w[0] != "format" && !sawFormat) fail(m_file, m_line, "the PLY header has no 'format' line first");
            if (w[0] == "format") {
                header.format = readFormat(w);
                sawFormat = true;
            } else if (w[0] == "element") {
                header.elements.push_back(readElement(w));
            } else if (w[0] == "property") {
                if (header.elements.empty()) fail(m_file, m_line, "PLY property before any element");
                header.elements.back().properties.push_back(readProperty(w));
            } else {
                fail(m_file, m_line, "unknown PLY header line '" + std::string(w[0]) + "'");
            }
        }
        if (!sawFormat) fail(m_file, m_line, "the PLY header has no 'format' line");
        header.bytes = m_at;
        header.lines = m_line;
        return header;
    }

private:
    std::optional<std::string_view> nextLine()
    {
        if (m_at >= m_text.size()) return std::nullopt;
        const size_t end = m_text.find('\n', m_at);
        if (end == std::string::npos) return std::nullopt; // the header's last line needs its newline too
        std::string_view line(m_text.data() + m_at, end - m_at);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        m_at = end + 1;
        ++m_line;
        return line;
    }

    Format readFormat(const std::vector<std::string_view>& w) const
    {
        if (w.size() != 3 || w[2] != "1.0") {
            fail(m_file, m_line,
                 "the PLY format line must read 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
        }
        if (w[1] == "ascii") return Format::Ascii;
        if (w[1] == "binary_little_endian") return Format::LittleEndian;
        if (w[1] == "binary_big_endian") return Format::BigEndian;
        fail(m_file, m_line, "unknown PLY format '" + std::string(w[1]) + "'");
    }

    Element readElement(const std::vector<std::string_view>& w) const
    {
        if (w.size() != 3) fail(m_file, m_line, "a PLY element line must read 'element <name> <count>'");
        Element element{std::string(w[1]), 0, m_line, {}};
        const auto [end, error] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), element.count);
        if (error != std::errc() || end != w[2].data() + w[2].size()) {
            fail(m_file, m_line,
                 "PLY element '" + element.name + "' has count '" + std::string(w[2]) +
                     "', not a non-negative integer");
        }
        if (element.name == "tristrips") {
            fail(m_file, m_line,
                 "PLY triangle strips (element 'tristrips') are not supported; convert the strips to faces "
                 "(e.g. with MeshLab)");
        }
        return element;
    }

    Property readProperty(const std::vector<std::string_view>& w) const
    {
        if (w.size() >= 2 && w[1] == "list") {
            if (w.size() != 5) {
                fail(m_file, m_line, "a PLY list property must read 'property list <count type> <type> <name>'");
            }
            const std::optional<Scalar> count = scalarType(w[2]), type = scalarType(w[3]);
            if (!count || !type) fail(m_file, m_line, "unknown PLY type '" + std::string(count ? w[3] : w[2]) + "'");
            if (!isInteger(*count)) fail(m_file, m_line, "a PLY list's count type must be an integer type");
            return Property{std::string(w[4]), *type, count};
        }
        if (w.size() != 3) fail(m_file, m_line, "a PLY property line must read 'property <type> <name>'");
        const std::optional<Scalar> type = scalarType(w[1]);
        if (!type) fail(m_file, m_line, "unknown PLY type '" + std::string(w[1]) + "'");
        return Property{std::string(w[2]), *type, std::nullopt};
    }

    const fs::path& m_file;
    const std::string& m_text;
    size_t m_at = 0;
    int m_line = 0;
};

// ---------------------------------------------------------------------------
// Body: one source of values per format, with a position for messages.

class BodyReader {
public:
    BodyReader(const fs::path& file, const std::string& data, const Header& header)
        : m_file(file),
          m_data(data),
          m_format(header.format),
          m_at(header.bytes),
          m_line(header.lines)
    {
    }

    /// Starts an instance: in ASCII, the next non-empty line.
    void beginInstance(const Element& element, uint64_t index)
    {
        m_element = &element;
        m_index = index;
        m_instanceStart = m_at;
        if (m_format != Format::Ascii) return;
        for (;;) {
            if (m_at >= m_data.size()) failHere("the file ends before " + where());
            const size_t end = std::min(m_data.find('\n', m_at), m_data.size());
            m_words = words(std::string_view(m_data).substr(m_at, end - m_at));
            m_at = end + 1;
            ++m_line;
            m_word = 0;
            if (!m_words.empty()) return;
        }
    }

    /// Ends an instance: in ASCII, its line must hold nothing more.
    void endInstance()
    {
        if (m_format == Format::Ascii && m_word != m_words.size()) {
            failHere(where() + " has " + std::to_string(m_words.size()) + " values, more than its header declares");
        }
    }

    double value(Scalar type)
    {
        if (m_format == Format::Ascii) return asciiValue(type);
        return binaryValue(type);
    }

    /// Names the ASCII line, or the byte where the binary instance starts.
    [[noreturn]] void failHere(const std::string& message) const
    {
        if (m_format == Format::Ascii) fail(m_file, m_line, message);
        fail(m_file, 0, "byte " + std::to_string(m_instanceStart) + ": " + message);
    }

    std::string where() const { return m_element->name + " " + std::to_string(m_index) + " (counting from 0)"; }

private:
    double asciiValue(Scalar type)
    {
        if (m_word >= m_words.size()) failHere(where() + " has fewer values than its header declares");
        const std::string_view word = m_words[m_word++];
        double value = 0.0;
        const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
        if (error != std::errc() || end != word.data() + word.size()) {
            // from_chars reports out-of-range values as errors: name them apart from non-numbers.
            if (error == std::errc::result_out_of_range)
                failHere(where() + " has a value out of range: '" + std::string(word) + "'");
            failHere(where() + " has '" + std::string(word) + "', not a number");
        }
        if (isInteger(type) && value != std::floor(value)) {
            failHere(where() + " has '" + std::string(word) + "' where its header declares an integer");
        }
        return value;
    }

    template <typename T>
    T readRaw()
    {
        if (m_data.size() - std::min(m_at, m_data.size()) < sizeof(T)) failHere("the file ends inside " + where());
        char bytes[sizeof(T)];
        std::memcpy(bytes, m_data.data() + m_at, sizeof(T));
        m_at += sizeof(T);
        if ((m_format == Format::BigEndian) != (std::endian::native == std::endian::big)) {
            std::reverse(bytes, bytes + sizeof(T));
        }
        T value;
        std::memcpy(&value, bytes, sizeof(T));
        return value;
    }

    double binaryValue(Scalar type)
    {
        switch (type) {
        case Scalar::Int8: return readRaw<int8_t>();
        case Scalar::UInt8: return readRaw<uint8_t>();
        case Scalar::Int16: return readRaw<int16_t>();
        case Scalar::UInt16: return readRaw<uint16_t>();
        case Scalar::Int32: return readRaw<int32_t>();
        case Scalar::UInt32: return readRaw<uint32_t>();
        case Scalar::Float32: return readRaw<float>();
        case Scalar::Float64: return readRaw<double>();
        }
        return 0.0;
    }

    const fs::path& m_file;
    const std::string& m_data;
    Format m_format;
    size_t m_at;
    int m_line;
    std::vector<std::string_view> m_words;
    size_t m_word = 0;
    const Element* m_element = nullptr;
    uint64_t m_index = 0;
    size_t m_instanceStart = 0;
};

// ---------------------------------------------------------------------------
// Which properties carry what vkrt reads.

std::optional<size_t> findProperty(const Element& element, std::initializer_list<std::string_view> names)
{
    for (const std::string_view name : names) {
        for (size_t i = 0; i < element.properties.size(); ++i) {
            if (element.properties[i].name == name && !element.properties[i].countType) return i;
        }
    }
    return std::nullopt;
}

struct VertexLayout {
    std::array<size_t, 3> position{};
    std::optional<std::array<size_t, 3>> normal;
    std::optional<std::array<size_t, 2>> uv;
};

VertexLayout vertexLayout(const fs::path& file, const Element& vertex)
{
    VertexLayout layout;
    const char* axes[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
        const std::optional<size_t> found = findProperty(vertex, {axes[a]});
        if (!found)
            fail(file, vertex.line, "PLY element 'vertex' has no scalar property '" + std::string(axes[a]) + "'");
        layout.position[a] = *found;
    }
    const auto nx = findProperty(vertex, {"nx"}), ny = findProperty(vertex, {"ny"}), nz = findProperty(vertex, {"nz"});
    if (nx && ny && nz) layout.normal = std::array<size_t, 3>{*nx, *ny, *nz};
    const auto u = findProperty(vertex, {"u", "s", "texture_u", "texture_s"});
    const auto v = findProperty(vertex, {"v", "t", "texture_v", "texture_t"});
    if (u && v) layout.uv = std::array<size_t, 2>{*u, *v};
    return layout;
}

std::optional<size_t> faceIndexList(const Element& face)
{
    for (size_t i = 0; i < face.properties.size(); ++i) {
        const Property& p = face.properties[i];
        if (p.countType && (p.name == "vertex_indices" || p.name == "vertex_index")) return i;
    }
    return std::nullopt;
}

/// The least number of body bytes an element's instances take: in binary,
/// their scalars and list counts; in ASCII, one character and one separator
/// per value.
uint64_t minBodyBytes(const Element& element, Format format)
{
    const uint64_t perInstance = format == Format::Ascii ? 2 * element.properties.size() : element.minBinaryBytes();
    if (element.count != 0 && perInstance > UINT64_MAX / element.count) return UINT64_MAX;
    return element.count * perInstance;
}

/// Refuses counts the file cannot hold before anything is allocated for them.
void checkCountsFit(const fs::path& file, const Header& header, uint64_t fileBytes)
{
    uint64_t available = fileBytes - header.bytes + (header.format == Format::Ascii ? 1 : 0);
    for (const Element& element : header.elements) {
        if (element.count > 0 && element.properties.empty()) {
            fail(file, element.line,
                 "PLY element '" + element.name + "' has " + std::to_string(element.count) +
                     " instances but no properties");
        }
        const uint64_t needed = minBodyBytes(element, header.format);
        if (needed > available) {
            fail(file, element.line,
                 "PLY element '" + element.name + "' declares " + std::to_string(element.count) +
                     " instances, more than the rest of the file can hold (" + std::to_string(available) +
                     " bytes); the file is truncated or its header is wrong");
        }
        available -= needed;
    }
}

std::string readWholeFile(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) fail(file, 0, "cannot open the file");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// ---------------------------------------------------------------------------
// Reading the body into a MeshData.

std::string describeVertex(const glm::vec3& v)
{
    std::ostringstream text;
    text << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return text.str();
}

class PlyMeshBuilder {
public:
    PlyMeshBuilder(const fs::path& file, BodyReader& body) : m_file(file), m_body(body) {}

    void readVertices(const Element& element)
    {
        const VertexLayout layout = vertexLayout(m_file, element);
        m_mesh.positions.reserve(element.count);
        if (layout.normal) m_mesh.normals.reserve(element.count);
        if (layout.uv) m_mesh.uvs.reserve(element.count);
        std::vector<double> values(element.properties.size());
        for (uint64_t i = 0; i < element.count; ++i) {
            m_body.beginInstance(element, i);
            for (size_t p = 0; p < element.properties.size(); ++p) values[p] = readProperty(element.properties[p]);
            m_body.endInstance();
            const glm::vec3 position = pick3(values, layout.position);
            if (!allFinite(position))
                m_body.failHere(m_body.where() + " has a non-finite coordinate " + describeVertex(position));
            m_mesh.positions.push_back(position);
            if (layout.normal) {
                const glm::vec3 n = pick3(values, *layout.normal);
                if (!allFinite(n)) m_body.failHere(m_body.where() + " has a non-finite normal " + describeVertex(n));
                const float length = glm::length(n);
                m_mesh.normals.push_back(length > 0.0f && std::isfinite(length) ? n / length : glm::vec3(0.0f));
            }
            if (layout.uv) {
                const glm::vec2 uv{float(values[(*layout.uv)[0]]), float(values[(*layout.uv)[1]])};
                if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
                    m_body.failHere(m_body.where() + " has a non-finite texture coordinate");
                }
                m_mesh.uvs.push_back(uv);
            }
        }
    }

    void readFaces(const Element& element, uint64_t vertexCount)
    {
        const std::optional<size_t> list = faceIndexList(element);
        if (!list) fail(m_file, element.line, "PLY element 'face' has no list property 'vertex_indices'");
        std::vector<uint32_t> corners;
        for (uint64_t i = 0; i < element.count; ++i) {
            m_body.beginInstance(element, i);
            for (size_t p = 0; p < element.properties.size(); ++p) {
                if (p == *list) {
                    readCorners(element.properties[p], vertexCount, corners);
                } else {
                    readProperty(element.properties[p]);
                }
            }
            m_body.endInstance();
            // A fan: what assimp's Triangulate gave for the convex polygons of real files.
            for (size_t c = 2; c < corners.size(); ++c)
                m_mesh.triangles.emplace_back(corners[0], corners[c - 1], corners[c]);
        }
    }

    void skip(const Element& element)
    {
        for (uint64_t i = 0; i < element.count; ++i) {
            m_body.beginInstance(element, i);
            for (const Property& p : element.properties) readProperty(p);
            m_body.endInstance();
        }
    }

    MeshData take() { return std::move(m_mesh); }

private:
    static bool allFinite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

    static glm::vec3 pick3(const std::vector<double>& values, const std::array<size_t, 3>& at)
    {
        return {float(values[at[0]]), float(values[at[1]]), float(values[at[2]])};
    }

    /// A scalar, or a list read past (its entries are not kept); returns the scalar.
    double readProperty(const Property& p)
    {
        if (!p.countType) return m_body.value(p.type);
        const double count = m_body.value(*p.countType);
        if (count < 0) m_body.failHere(m_body.where() + " has a list of negative length");
        for (double e = 0; e < count; ++e) m_body.value(p.type);
        return 0.0;
    }

    void readCorners(const Property& p, uint64_t vertexCount, std::vector<uint32_t>& corners)
    {
        corners.clear();
        if (!isInteger(p.type)) m_body.failHere("PLY face indices must have an integer type");
        const double count = m_body.value(*p.countType);
        if (count < 0) m_body.failHere(m_body.where() + " has a list of negative length");
        for (double e = 0; e < count; ++e) {
            const double index = m_body.value(p.type);
            if (index < 0 || index >= double(vertexCount)) {
                std::ostringstream value;
                value << index;
                m_body.failHere(m_body.where() + " uses vertex " + value.str() + " of only " +
                                std::to_string(vertexCount));
            }
            corners.push_back(uint32_t(index));
        }
    }

    const fs::path& m_file;
    BodyReader& m_body;
    MeshData m_mesh;
};

} // namespace

MeshData readPlyFile(const fs::path& file)
{
    const std::string data = readWholeFile(file);
    const Header header = HeaderReader(file, data.substr(0, kMaxHeaderBytes)).read();
    checkCountsFit(file, header, data.size());
    const auto vertex = std::find_if(header.elements.begin(), header.elements.end(),
                                     [](const Element& e) { return e.name == "vertex"; });
    if (vertex == header.elements.end()) fail(file, header.lines, "the PLY header declares no 'vertex' element");
    if (vertex->count > std::numeric_limits<uint32_t>::max()) fail(file, vertex->line, "more than 2^32 vertices");
    BodyReader body(file, data, header);
    PlyMeshBuilder builder(file, body);
    for (const Element& element : header.elements) {
        if (&element == &*vertex) {
            builder.readVertices(element);
        } else if (element.name == "face") {
            builder.readFaces(element, vertex->count);
        } else {
            builder.skip(element);
        }
    }
    MeshData mesh = builder.take();
    if (mesh.triangles.empty())
        fail(file, 0, "no triangles in " + file.string() + " (it has no faces of 3 or more vertices)");
    return mesh;
}

} // namespace vkrt
