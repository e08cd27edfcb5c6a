#include "view/ViewerScript.h"

#include "util/Error.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace vkrt {

namespace {

struct Signature {
    int numbers; ///< -1: one text argument instead
};

const std::map<std::string, Signature> kCommands = {
    {"frames", {1}},   {"orbit", {2}}, {"fly", {3}},   {"zoom", {1}},
    {"exposure", {1}}, {"key", {-1}},  {"save", {-1}}, {"screenshot", {-1}}, {"focus", {2}},
    {"open", {-1}},
};

const char* const kKeys[] = {"S", "R", "I", "P", "H", "+", "-", "F"};

[[noreturn]] void fail(const std::string& path, int line, size_t column, const std::string& message)
{
    throw InputError(SourceLocation{path, line, int(column) + 1}.str() + ": " + message);
}

/// Splits a line into words with their starting columns.
std::vector<std::pair<std::string, size_t>> words(const std::string& line)
{
    std::vector<std::pair<std::string, size_t>> result;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        if (i >= line.size() || line[i] == '#') break;
        size_t start = i;
        while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        result.emplace_back(line.substr(start, i - start), start);
    }
    return result;
}

double number(const std::string& path, int line, const std::pair<std::string, size_t>& word)
{
    size_t used = 0;
    double value = 0;
    try {
        value = std::stod(word.first, &used);
    } catch (...) {
        used = 0;
    }
    if (used != word.first.size() || !std::isfinite(value))
        fail(path, line, word.second, "expected a finite number, got '" + word.first + "'");
    return value;
}

ViewerCommand parseLine(const std::vector<std::pair<std::string, size_t>>& w, const std::string& path, int line)
{
    auto it = kCommands.find(w[0].first);
    if (it == kCommands.end())
        fail(path, line, w[0].second,
             "unknown command '" + w[0].first + "' (frames, orbit, fly, zoom, exposure, key, save, screenshot, focus, open)");
    int expected = it->second.numbers < 0 ? 1 : it->second.numbers;
    if (int(w.size()) - 1 != expected)
        fail(path, line, w[0].second,
             "'" + w[0].first + "' takes " + std::to_string(expected) + " argument(s), got " +
                 std::to_string(w.size() - 1));
    ViewerCommand command{w[0].first, {}, "", line};
    if (it->second.numbers < 0) command.text = w[1].first;
    else
        for (size_t i = 1; i < w.size(); ++i) command.numbers.push_back(number(path, line, w[i]));
    if (command.name == "frames" &&
        (command.numbers[0] < 0 || command.numbers[0] != std::floor(command.numbers[0]) || command.numbers[0] > 1e6))
        fail(path, line, w[1].second, "frames needs a whole number from 0 to 1000000");
    if (command.name == "zoom" && !(command.numbers[0] > 0)) fail(path, line, w[1].second, "zoom factor must be > 0");
    if (command.name == "focus")
        for (size_t i = 0; i < 2; ++i)
            if (!(command.numbers[i] >= 0 && command.numbers[i] < 1))
                fail(path, line, w[i + 1].second, "focus takes the point as fractions of the image in [0, 1)");
    if (command.name == "key" && std::find(std::begin(kKeys), std::end(kKeys), command.text) == std::end(kKeys))
        fail(path, line, w[1].second, "unknown key '" + command.text + "' (S R I P H + - F)");
    return command;
}

} // namespace

std::vector<ViewerCommand> parseViewerScript(const std::string& text, const std::string& path)
{
    std::vector<ViewerCommand> commands;
    std::istringstream in(text);
    std::string lineText;
    for (int line = 1; std::getline(in, lineText); ++line) {
        auto w = words(lineText);
        if (!w.empty()) commands.push_back(parseLine(w, path, line));
    }
    return commands;
}

std::vector<ViewerCommand> readViewerScript(const std::filesystem::path& path)
{
    std::ifstream in(path);
    if (!in) throw InputError("--script " + path.string() + ": cannot read file");
    std::stringstream text;
    text << in.rdbuf();
    return parseViewerScript(text.str(), path.string());
}

} // namespace vkrt
