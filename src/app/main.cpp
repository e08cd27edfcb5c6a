// vkrt: a Vulkan compute ray tracer. This file only wires subcommands.
#include "app/Commands.h"
#include "app/ManPage.h"
#include "app/Suggestions.h"
#include "app/VectorWidthRelaunch.h"
#include "util/Error.h"
#include "util/Signals.h"

#include <CLI/CLI.hpp>

#include <cstdio>

int main(int argc, char** argv)
{
    vkrt::rememberCommandLine(argc, argv); // --vector-width may start vkrt again with it
    // Temporary outputs go with any SIGINT/SIGTERM/SIGHUP; a driver crash is named as such.
    vkrt::installSignalHandlers({vkrt::kExitInterrupted, vkrt::kExitDriverCrashed});
    CLI::App app("vkrt - Vulkan compute ray tracer", "vkrt");
    app.set_version_flag(
        "--version", [] { return vkrt::versionText(); },
        "Print the version, the commit it was built "
        "from and the Vulkan device it would use");
    app.require_subcommand(1);
    std::vector<std::pair<CLI::App*, vkrt::CommandRunner>> commands;
    // Each add*Command registers one subcommand: pair it with its runner.
    auto add = [&](vkrt::CommandRunner runner) {
        commands.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(runner));
    };
    add(vkrt::addRenderCommand(app));
    add(vkrt::addViewCommand(app));
    add(vkrt::addInfoCommand(app));
    add(vkrt::addCompareCommand(app));
    add(vkrt::addMergeCommand(app));
    add(vkrt::addRegressCommand(app));
    add(vkrt::addDevicesCommand(app));
    // Hidden: the build writes the manual page with it (build/vkrt.1).
    CLI::App* man = app.add_subcommand("man", "Print the manual page (roff) made from these option definitions");
    man->group("");
    commands.emplace_back(man, [&app] {
        std::fputs(vkrt::manPage(app).c_str(), stdout);
        return int(vkrt::kExitOk);
    });

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int code = app.exit(e);
        if (code != 0)
            if (auto hint = vkrt::commandLineSuggestion(app, argc, argv))
                std::fprintf(stderr, "vkrt: %s\n", hint->c_str());
        return code == 0 ? vkrt::kExitOk : vkrt::kExitBadInput;
    }
    try {
        for (auto& [command, run] : commands)
            if (command->parsed()) return run();
    } catch (const vkrt::InputError& e) {
        std::fprintf(stderr, "vkrt: error: %s\n", e.what());
        return vkrt::kExitBadInput;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vkrt: error: %s\n", e.what());
        return vkrt::kExitFailure;
    }
    return vkrt::kExitFailure;
}
