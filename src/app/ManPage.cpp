#include "app/ManPage.h"

#include <sstream>

namespace vkrt {

namespace {

/// Text as roff reads it: backslashes doubled, hyphens escaped, and a line
/// that would start with a control character ('.' or '\'') guarded.
std::string roff(const std::string& text)
{
    std::string out;
    for (char c : text) {
        if (c == '\\') out += "\\\\";
        else if (c == '-') out += "\\-";
        else out += c;
    }
    if (!out.empty() && (out[0] == '.' || out[0] == '\'')) out = "\\&" + out;
    return out;
}

/// "-o, --output TEXT" as the option's names and value.
std::string optionLabel(const CLI::Option& option)
{
    std::string label;
    for (const std::string& name : option.get_snames()) label += (label.empty() ? "-" : ", -") + name;
    for (const std::string& name : option.get_lnames()) label += (label.empty() ? "--" : ", --") + name;
    if (label.empty()) label = option.get_name(); // a positional
    if (option.get_type_size() != 0 && !option.get_lnames().empty()) label += " " + option.get_type_name();
    return label;
}

void writeOptions(std::ostringstream& page, const CLI::App& command)
{
    for (const CLI::Option* option : command.get_options()) {
        if (option->get_group().empty()) continue; // hidden: test and measurement hooks
        page << ".TP\n.B " << roff(optionLabel(*option)) << "\n" << roff(option->get_description()) << "\n";
    }
}

} // namespace

std::string manPage(const CLI::App& app)
{
    std::ostringstream page;
    page << ".TH VKRT 1 \"\" \"vkrt " << VKRT_VERSION << "\" \"User Commands\"\n"
         << ".SH NAME\nvkrt \\- a Vulkan compute ray tracer\n"
         << ".SH SYNOPSIS\n.B vkrt\n.I COMMAND\n[\\fIOPTIONS\\fR]\n"
         << ".SH DESCRIPTION\nA Vulkan compute ray tracer: scene files (TOML, or glTF) rendered by GLSL kernels "
            "compiled at run time, on any Vulkan device, lavapipe included. Each command below is "
            "\\fBvkrt COMMAND\\fR; \\fBvkrt COMMAND \\-\\-help\\fR prints the same options.\n"
         << ".SH OPTIONS\n";
    writeOptions(page, app);
    page << ".SH COMMANDS\n";
    for (const CLI::App* command : app.get_subcommands([](const CLI::App* sub) { return !sub->get_group().empty(); })) {
        page << ".SS " << roff(command->get_name()) << "\n" << roff(command->get_description()) << "\n";
        writeOptions(page, *command);
    }
    page << ".SH EXIT STATUS\n0 success; 1 failure; 2 bad input (a scene, a file or an option; the message names "
            "it); 3 Vulkan validation messages; 4 a comparison or regression failed; 5 the Vulkan driver crashed; "
            "130 interrupted (what was rendered is written).\n"
         << ".SH FILES\nThe docs of the source tree: README.md, docs/scene-format.md (scene files), "
            "docs/machine-output.md (\\-\\-json), docs/regress.md (the regression suite), docs/viewer.md, "
            "docs/python.md.\n"
         << ".SH SEE ALSO\n\\fBvkrt\\-make\\-sky\\fR, \\fBvkrt\\-make\\-mesh\\fR\n";
    return page.str();
}

} // namespace vkrt
