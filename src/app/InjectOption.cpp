#include "app/InjectOption.h"

#include "gpu/SpirvFault.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <optional>

namespace vkrt {

namespace {

/// CLI11's check: "" for a valid spec, else what is wrong with it.
std::string checkFault(const std::string& spec)
{
    try {
        parseSpirvFault(spec);
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

} // namespace

void addInjectOption(CLI::App& command, std::string& fault)
{
    command
        .add_option("--inject", fault,
                    "Inject a SPIR-V fault into every kernel the driver runs, to measure what the tests catch: "
                    "scale:CLASS:EPS[:1inN] (CLASS's float results x (1 + EPS), all or 1 in N; FMul, FAdd, FSub, "
                    "FDiv, Sqrt, InverseSqrt, Exp, Log, Pow, Sin, Cos, Atan2, Acos, Exp2, Log2, Fma, RayQueryT), "
                    "compare:lt-le, compare:gt-ge (swap < and <=, > and >=), nan-minmax (min/max mishandle NaN), "
                    "neighbour-load[:1inN] (a storage-buffer element load reads the next element), "
                    "texel-offset[:1inN] (texelFetch reads the texel to the right), loop-cut:N (loops end after N "
                    "passes of an invocation in all), or the legal variation "
                    "contract (a * b + c fused into fma where not precise)")
        ->check(CLI::Validator(checkFault, ""))
        ->type_name("FAULT");
}

std::string applyInjectOption(const std::string& fault)
{
    if (fault.empty()) {
        std::optional<SpirvFault> inherited = spirvFaultFromEnvironment();
        return inherited ? inherited->spec : "";
    }
    if (setenv(kInjectFaultVariable, fault.c_str(), 1) != 0)
        throw InputError(std::string("--inject: cannot set ") + kInjectFaultVariable);
    return fault;
}

} // namespace vkrt
