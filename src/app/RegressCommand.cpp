// `vkrt regress`: the regression suite (src/regress/RegressionRun.cpp).
#include "app/Commands.h"
#include "app/ExitCodes.h"
#include "io/OutputPaths.h"
#include "regress/RegressionRun.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <memory>

namespace vkrt {

namespace {

/// Before any case runs: the reports must not overwrite the suite manifest or each other. The
/// report directory is made first, since --junit is often inside it (DIR/junit.xml).
void checkRegressFiles(const RegressOptions& options)
{
    if (!options.reportDir.empty()) createReportDir(options.reportDir);
    const NamedFile suite{"the suite manifest", options.suite};
    const NamedFile junit{"--junit", options.junit};
    checkOutputs({suite}, {junit});
    if (!options.reportDir.empty())
        refuseOverlappingFiles({suite, junit}, {{"--report-dir's report.md", options.reportDir / "report.md"}});
}

} // namespace

CommandRunner addRegressCommand(CLI::App& app)
{
    auto o = std::make_shared<RegressOptions>();
    auto defines = std::make_shared<std::vector<std::string>>();
    o->suite = VKRT_DEFAULT_SUITE;
    CLI::App* cmd = app.add_subcommand("regress", "Run the regression suite against its references");
    cmd->add_option("--suite", o->suite, "Suite manifest (default: tests/regress/suite.toml)");
    cmd->add_option("--filter", o->filters, "Only cases whose name contains this (repeatable: any of them)");
    cmd->add_option("--driver", o->driver, "Vulkan ICD manifest (JSON) of the driver to test");
    cmd->add_option("--device", o->device, "Vulkan device index or name");
    cmd->add_option("--junit", o->junit, "Write JUnit XML here");
    cmd->add_option("--report-dir", o->reportDir, "Write report.md and failure images here");
    cmd->add_flag("--update", o->update, "Regenerate the vkrt-made references (never the Mitsuba ones)");
    cmd->add_option("--seed-offset", o->seedOffset, "Added to the suite's seed (for repeated runs)");
    cmd->add_flag("--fail-on-slowdown", o->failOnSlowdown, "Fail cases slower than baseline x max_slowdown");
    cmd->add_option("--kernel-define", *defines, "NAME=VALUE define for every kernel (test hooks)")->group("");
    return [o, defines] {
        checkRegressFiles(*o);
        o->kernelDefines = parseKernelDefines(*defines);
        return exitCodeFor(runRegression(*o));
    };
}

} // namespace vkrt
