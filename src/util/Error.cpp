#include "util/Error.h"

namespace vkrt {

void failCheck(const char* expression, const char* file, int line)
{
    throw InternalError(std::string("internal error: check '") + expression + "' failed at " + file + ":" +
                        std::to_string(line));
}

void failInFile(const std::string& file, const std::string& message) { throw InputError(file + ": " + message); }

} // namespace vkrt
