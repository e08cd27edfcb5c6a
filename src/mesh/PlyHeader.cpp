#include "mesh/PlyHeader.h"

#include "util/Error.h"

#include <charconv>
#include <cstdint>
#include <fstream>
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

/// Bytes of a scalar PLY type in a binary body; nullopt for an unknown type.
std::optional<uint64_t> scalarBytes(std::string_view type)
{
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
        type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return std::nullopt;
}

struct Element {
    std::string name;
    uint64_t count = 0;
    int line = 0;
    uint64_t minBinaryBytes = 0; // of one instance: scalars, and list counts with no entries
    uint64_t properties = 0;
};

enum class Format { Ascii, Binary };

struct Header {
    Format format = Format::Ascii;
    std::vector<Element> elements;
};

class HeaderReader {
public:
    HeaderReader(const fs::path& file, std::string text) : m_file(file), m_text(std::move(text)) {}

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
            if (w[0] == "format") {
                header.format = readFormat(w);
                sawFormat = true;
            } else if (w[0] == "element") {
                header.elements.push_back(readElement(w));
            } else if (w[0] == "property") {
                if (header.elements.empty()) fail(m_file, m_line, "PLY property before any element");
                readProperty(w, header.elements.back());
            } else {
                fail(m_file, m_line, "unknown PLY header line '" + std::string(w[0]) + "'");
            }
            if (w[0] != "format" && !sawFormat) fail(m_file, m_line, "the PLY header has no 'format' line first");
        }
        if (!sawFormat) fail(m_file, m_line, "the PLY header has no 'format' line");
        return header;
    }

    size_t headerBytes() const { return m_at; }

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
        if (w.size() != 3 || w[2] != "1.0")
            fail(m_file, m_line, "the PLY format line must read 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
        if (w[1] == "ascii") return Format::Ascii;
        if (w[1] == "binary_little_endian" || w[1] == "binary_big_endian") return Format::Binary;
        fail(m_file, m_line, "unknown PLY format '" + std::string(w[1]) + "'");
    }

    Element readElement(const std::vector<std::string_view>& w) const
    {
        if (w.size() != 3) fail(m_file, m_line, "a PLY element line must read 'element <name> <count>'");
        Element element{std::string(w[1]), 0, m_line};
        const auto [end, error] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), element.count);
        if (error != std::errc() || end != w[2].data() + w[2].size())
            fail(m_file, m_line, "PLY element '" + element.name + "' has count '" + std::string(w[2]) +
                                     "', not a non-negative integer");
        if (element.name == "tristrips") {
            fail(m_file, m_line,
                 "PLY triangle strips (element 'tristrips') are not supported: the Open Asset Import Library "
                 "loads only one triangle of each strip; convert the strips to faces (e.g. with MeshLab)");
        }
        return element;
    }

    void readProperty(const std::vector<std::string_view>& w, Element& element) const
    {
        if (w.size() >= 2 && w[1] == "list") {
            if (w.size() != 5) fail(m_file, m_line, "a PLY list property must read 'property list <count type> <type> <name>'");
            const std::optional<uint64_t> countBytes = scalarBytes(w[2]);
            if (!countBytes || !scalarBytes(w[3]))
                fail(m_file, m_line, "unknown PLY type '" + std::string(countBytes ? w[3] : w[2]) + "'");
            element.minBinaryBytes += *countBytes;
        } else {
            if (w.size() != 3) fail(m_file, m_line, "a PLY property line must read 'property <type> <name>'");
            const std::optional<uint64_t> bytes = scalarBytes(w[1]);
            if (!bytes) fail(m_file, m_line, "unknown PLY type '" + std::string(w[1]) + "'");
            element.minBinaryBytes += *bytes;
        }
        ++element.properties;
    }

    const fs::path& m_file;
    std::string m_text;
    size_t m_at = 0;
    int m_line = 0;
};

std::string readPrefix(const fs::path& file, size_t bytes)
{
    std::ifstream in(file, std::ios::binary);
    std::string text(bytes, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<size_t>(in.gcount()));
    return text;
}

/// The least number of body bytes an element's instances take: in binary,
/// their scalars and list counts; in ASCII, one character and one separator
/// per value.
uint64_t minBodyBytes(const Element& element, Format format)
{
    const uint64_t perInstance = format == Format::Binary ? element.minBinaryBytes : 2 * element.properties;
    if (element.count != 0 && perInstance > UINT64_MAX / element.count) return UINT64_MAX;
    return element.count * perInstance;
}

} // namespace

void checkPlyHeader(const fs::path& file)
{
    HeaderReader reader(file, readPrefix(file, kMaxHeaderBytes));
    const Header header = reader.read();
    std::error_code error;
    const uintmax_t size = fs::file_size(file, error);
    if (error) fail(file, 0, "cannot read its size: " + error.message());
    // ASCII bodies may omit the last separator.
    uint64_t available = size - reader.headerBytes() + (header.format == Format::Ascii ? 1 : 0);
    for (const Element& element : header.elements) {
        if (element.count > 0 && element.properties == 0)
            fail(file, element.line, "PLY element '" + element.name + "' has " + std::to_string(element.count) +
                                         " instances but no properties");
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

} // namespace vkrt
