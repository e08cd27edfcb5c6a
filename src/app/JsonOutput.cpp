#include "app/JsonOutput.h"

#include "io/AtomicFile.h"
#include "scene/Scene.h"
#include "util/Error.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace vkrt {

NamedFile jsonOutputFile(const std::string& path) { return {"--json", path == "-" ? std::string() : path}; }

JsonObject jsonDocument(const std::string& command)
{
    return {{"schema", kMachineOutputSchema}, {"command", command}, {"vkrtVersion", VKRT_VERSION}};
}

void writeJson(const std::string& path, const JsonObject& document)
{
    // Invalid UTF-8 (a scene path's bytes) is replaced, not thrown on after the render.
    const std::string text = document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    if (path != "-") return writeBytesAtomically(path, text);
    // One write of the whole text, then a checked flush: a reader of a pipe sees all or an error.
    if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
        throw InputError("--json -: cannot write to standard output: " + std::string(std::strerror(errno)));
}

} // namespace vkrt
