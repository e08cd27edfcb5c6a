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

/// Before any case runs: the reports must not overwrite the suite manifest,
/// the baseline files or each other. The report directory is made first, since
/// --junit is often inside it (DIR/junit.xml).
void checkRegressFiles(const RegressOptions& options)
{
    if (!options.reportDir.empty()) createReportDir(options.reportDir);
    const std::vector<NamedFile> inputs{{"the suite manifest", options.suite},
                                        {"--baseline", options.baseline},
                                        {"--flakes", options.flakes},
                                        {"--skips", options.skips}};
    const NamedFile junit{"--junit", options.junit};
    checkOutputs(inputs, {junit});
    if (options.reportDir.empty()) return;
    std::vector<NamedFile> written{junit};
    for (const char* file : {"report.md", "results.csv", "failures.csv", "compare.csv"})
        written.push_back({std::string("--report-dir's ") + file, options.reportDir / file});
    refuseOverlappingFiles(inputs, written);
}

/// The options only the command line knows are set: whether --jobs and --case-timeout were given.
struct CommandLineExtras {
    unsigned jobs = 0;
    CLI::Option* jobsOption = nullptr;
    double caseTimeout = 0.0;
    CLI::Option* caseTimeoutOption = nullptr;
};

void applyExtras(RegressOptions& o, const CommandLineExtras& extras)
{
    if (extras.jobsOption->count()) o.jobs = extras.jobs;
    if (extras.caseTimeoutOption->count()) o.caseTimeout = extras.caseTimeout;
}

/// The child process's options (regress/AttemptPool.cpp gives them): hidden from --help.
void addChildOptions(CLI::App* cmd, RegressOptions& o)
{
    cmd->add_option("--run-case", o.runCase, "Make one attempt at this case (a child of vkrt regress)")->group("");
    cmd->add_option("--case-result", o.caseResult, "Write the attempt here (JSON)")->group("");
    cmd->add_option("--case-image", o.caseImage, "Write the render here (EXR with its variance)")->group("");
    cmd->add_option("--attempt", o.attempt, "1, or 2 for the re-run")->group("")->check(CLI::Range(1, 2));
}

} // namespace

CommandRunner addRegressCommand(CLI::App& app)
{
    auto o = std::make_shared<RegressOptions>();
    auto defines = std::make_shared<std::vector<std::string>>();
    auto extras = std::make_shared<CommandLineExtras>();
    o->suite = VKRT_DEFAULT_SUITE;
    CLI::App* cmd = app.add_subcommand("regress", "Run the regression suite against its references");
    cmd->add_option("--suite", o->suite, "Suite manifest (default: tests/regress/suite.toml)");
    cmd->add_option("--filter", o->filters, "Only cases whose name contains this (repeatable: any of them)");
    cmd->add_option("--driver", o->driver, "Vulkan ICD manifest (JSON) of the driver to test");
    cmd->add_option("--device", o->device, "Vulkan device index or name");
    cmd->add_option("--junit", o->junit, "Write JUnit XML here");
    cmd->add_option("--report-dir", o->reportDir, "Write report.md, results.csv, failures.csv and failure images here");
    cmd->add_flag("--update", o->update, "Regenerate the vkrt-made references (never the Mitsuba ones)");
    cmd->add_option("--seed-offset", o->seedOffset, "Added to the suite's seed (for repeated runs)");
    cmd->add_flag("--fail-on-slowdown", o->failOnSlowdown, "Fail cases slower than baseline x max_slowdown");
    extras->jobsOption = cmd->add_option("--jobs", extras->jobs,
                                         "Cases at once, each in a child process; 0: in this process (default: "
                                         "the number of cores; 1 with --fail-on-slowdown or --compare-drivers)");
    extras->caseTimeoutOption = cmd->add_option("--case-timeout", extras->caseTimeout,
                                                "Seconds a case's process may run (default: from "
                                                "its baseline_seconds, docs/regress.md)")
                                    ->check(CLI::PositiveNumber);
    cmd->add_option("--baseline", o->baseline, "Expected failures: 'case-name,Status' lines (deqp-runner's fails.txt)");
    cmd->add_option("--flakes", o->flakes, "Known flaky cases: one regular expression per line");
    cmd->add_option("--skips", o->skips, "Cases not to run: one regular expression per line");
    cmd->add_option("--compare-drivers", o->compareDrivers,
                    "Run every case on two drivers (ICD manifests A.json "
                    "B.json) and compare their images and times")
        ->expected(2);
    cmd->add_flag("--compare-accel", o->compareAccel,
                  "Run every case with both traversal backends (--accel own and driver) and compare their images "
                  "and times");
    addAccelOption(*cmd, o->accel);
    cmd->add_option("--kernel-define", *defines, "NAME=VALUE define for every kernel (test hooks)")->group("");
    addChildOptions(cmd, *o);
    return [o, defines, extras] {
        applyExtras(*o, *extras);
        if (o->runCase.empty()) checkRegressFiles(*o);
        o->kernelDefines = parseKernelDefines(*defines);
        return exitCodeFor(runRegression(*o));
    };
}

} // namespace vkrt
