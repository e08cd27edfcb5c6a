// `vkrt regress`: the regression suite (src/regress/RegressionRun.cpp).
#include "app/Commands.h"
#include "app/ExitCodes.h"
#include "app/InjectOption.h"
#include "io/OutputPaths.h"
#include "regress/RegressionRun.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <memory>
#include <string>

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
    std::string runCase;
    CLI::Option* runCaseOption = nullptr;
};

void applyExtras(RegressOptions& o, const CommandLineExtras& extras)
{
    if (extras.jobsOption->count()) o.jobs = extras.jobs;
    if (extras.caseTimeoutOption->count()) o.caseTimeout = extras.caseTimeout;
    // Given at all, even empty, it makes this process a child: a child that
    // took itself for the parent started the suite again, without end.
    if (extras.runCaseOption->count()) o.runCase = extras.runCase;
}

/// Seconds a case may run: a positive finite number (nan and inf would switch
/// the timeout off without a word).
std::string checkCaseTimeout(const std::string& text)
{
    try {
        size_t used = 0;
        const double seconds = std::stod(text, &used);
        if (used == text.size() && std::isfinite(seconds) && seconds > 0.0) return "";
    } catch (const std::exception&) {
    }
    return "must be a positive finite number of seconds, got '" + text.substr(0, 96) + "'";
}

/// The child process's options (regress/AttemptPool.cpp gives them): hidden from --help.
void addChildOptions(CLI::App* cmd, RegressOptions& o, CommandLineExtras& extras)
{
    extras.runCaseOption =
        cmd->add_option("--run-case", extras.runCase, "Make one attempt at this case (a child of vkrt regress)")
            ->group("");
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
                                    ->check(CLI::Validator(checkCaseTimeout, "SECONDS"));
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
    addInjectOption(*cmd, o->injectFault);
    cmd->add_option("--kernel-define", *defines, "NAME=VALUE define for every kernel (test hooks)")->group("");
    addChildOptions(cmd, *o, *extras);
    return [o, defines, extras] {
        applyExtras(*o, *extras);
        o->injectFault = applyInjectOption(o->injectFault); // before any case: the children inherit it
        if (!o->runCase) checkRegressFiles(*o);
        o->kernelDefines = parseKernelDefines(*defines);
        return exitCodeFor(runRegression(*o));
    };
}

} // namespace vkrt
