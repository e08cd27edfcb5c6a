#pragma once
// Scripted viewer sessions (`vkrt view --script FILE`), used by tests and for
// reproducible demos. One command per line; '#' starts a comment:
//   frames N            render and display N frames
//   orbit YAW PITCH     degrees (like dragging with the mouse)
//   fly RIGHT UP FWD    in units of the eye-target distance (like WASD/QE)
//   zoom FACTOR         multiply the field of view
//   exposure STOPS      set the display exposure
//   key NAME            press a key: S R I P H + - F
//   save PATH.exr       save the accumulation (EXR) and the displayed PNG beside it
//   screenshot PATH.png save the displayed image
#include <filesystem>
#include <string>
#include <vector>

namespace vkrt {

struct ViewerCommand {
    std::string name;
    std::vector<double> numbers;
    std::string text; ///< key name or path
    int line = 0;
};

/// Parses a script; errors are InputError "file:line:column: ...".
std::vector<ViewerCommand> parseViewerScript(const std::string& text, const std::string& path);
std::vector<ViewerCommand> readViewerScript(const std::filesystem::path& path);

} // namespace vkrt
