#include "app/Commands.h"

#include "util/Error.h"

namespace vkrt {

std::vector<Define> parseKernelDefines(const std::vector<std::string>& texts)
{
    std::vector<Define> defines;
    for (const std::string& d : texts) {
        auto eq = d.find('=');
        if (eq == std::string::npos || eq == 0) throw InputError("--kernel-define " + d + ": expected NAME=VALUE");
        defines.emplace_back(d.substr(0, eq), d.substr(eq + 1));
    }
    return defines;
}

} // namespace vkrt
