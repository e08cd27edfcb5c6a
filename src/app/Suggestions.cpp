#include "app/Suggestions.h"

#include "scene/TomlReader.h"

#include <map>
#include <string_view>
#include <vector>

namespace vkrt {

namespace {

/// Options as other renderers and tools spell them, and vkrt's name for each.
const std::map<std::string, std::string>& optionSynonyms()
{
    static const std::map<std::string, std::string> synonyms{
        {"--samples", "--spp"},
        {"--sample-count", "--spp"},
        {"--samples-per-pixel", "--spp"},
        {"-s", "--spp"},
        {"--output", "-o"},
        {"--out", "-o"},
        {"--resolution", "--width"},
        {"--res", "--width"},
        {"--xres", "--width"},
        {"--yres", "--height"},
        {"--threads", "--jobs"},
        {"--gpu", "--device"},
        {"--tonemap", "--filmic"},
        {"--ev", "--exposure"},
        {"--time-limit", "--time-budget"},
        {"--max-error", "--target-error"},
        {"--hdri", "--environment"},
        {"--env", "--environment"},
    };
    return synonyms;
}

std::optional<std::string> closest(const std::string& word, const std::vector<std::string>& names)
{
    std::vector<std::string_view> views(names.begin(), names.end());
    if (auto match = closestMatch(word, KeyList(views))) return std::string(*match);
    return std::nullopt;
}

std::vector<std::string> optionNames(const CLI::App& command)
{
    std::vector<std::string> names;
    for (const CLI::Option* option : command.get_options()) {
        for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
        for (const std::string& name : option->get_snames()) names.push_back("-" + name);
    }
    return names;
}

bool isOption(const CLI::App& command, const std::string& word)
{
    const std::vector<std::string> names = optionNames(command);
    return std::find(names.begin(), names.end(), word) != names.end();
}

} // namespace

std::optional<std::string> commandLineSuggestion(CLI::App& app, int argc, const char* const* argv)
{
    if (argc < 2) return std::nullopt;
    std::vector<std::string> commands;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) commands.push_back(sub->get_name());
    const std::string first = argv[1];
    CLI::App* command = nullptr;
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
        if (sub->get_name() == first) command = sub;
    if (!command) {
        if (first.starts_with("-")) return std::nullopt;
        if (auto match = closest(first, commands))
            return "did you mean `vkrt " + *match + "`? (`vkrt --help` lists the commands)";
        return "`" + first + "` is not a command; `vkrt --help` lists them";
    }
    for (int i = 2; i < argc; ++i) {
        std::string word = argv[i];
        if (!word.starts_with("-") || word == "-" || word == "--") continue;
        if (const size_t equals = word.find('='); equals != std::string::npos) word.resize(equals);
        if (isOption(*command, word)) continue;
        const auto synonym = optionSynonyms().find(word);
        if (synonym != optionSynonyms().end() && isOption(*command, synonym->second))
            return "did you mean " + synonym->second + "? (`vkrt " + command->get_name() +
                   " --help` lists the options)";
        if (auto match = closest(word, optionNames(*command)))
            return "did you mean " + *match + "? (`vkrt " + command->get_name() + " --help` lists the options)";
        return std::nullopt;
    }
    return std::nullopt;
}

} // namespace vkrt
