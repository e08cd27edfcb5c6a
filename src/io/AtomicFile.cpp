#include "io/AtomicFile.h"

#include "util/Error.h"

#include <random>

#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt {

void writeFileAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write)
{
    fs::path directory = path.has_parent_path() ? path.parent_path() : fs::path(".");
    if (!fs::is_directory(directory))
        throw InputError(path.string() + ": cannot write: directory '" + directory.string() + "' does not exist");
    std::random_device random;
    // Keep the extension last: some writers pick the format from it.
    fs::path temporary = directory / ("." + path.stem().string() + ".tmp-" + std::to_string(getpid()) + "-" +
                                      std::to_string(random()) + path.extension().string());
    std::error_code ignored;
    try {
        write(temporary);
    } catch (...) {
        fs::remove(temporary, ignored);
        throw;
    }
    std::error_code error;
    fs::rename(temporary, path, error);
    if (error) {
        fs::remove(temporary, ignored);
        throw InputError(path.string() + ": cannot write: " + error.message());
    }
}

} // namespace vkrt
