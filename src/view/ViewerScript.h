#pragma once
// Scripted viewer sessions (`vkrt view --script FILE`), used by tests and for
// reproducible demos (docs/viewer.md documents them for users: keep the two
// alike). One command per line; '#' starts a comment:
//   frames N            render and display N frames
//   orbit YAW PITCH     degrees (like dragging with the mouse)
//   fly RIGHT UP FWD    in units of the eye-target distance (like WASD/QE)
//   zoom FACTOR         multiply the field of view
//   exposure STOPS      set the display exposure
//   key NAME            press a key: S R I P H + - F
//   save PATH.exr       save the accumulation (EXR) and the displayed PNG beside it
//   screenshot PATH.png save the displayed image
//   focus X Y           click there: focus a thin lens on what is seen at (X, Y),
//                       fractions of the image in [0, 1) from its top left
//   open PATH           open another scene, as dropping its file on the window does
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
