#pragma once
// Error types shared by the whole library. Every user-facing failure is an
// exception whose what() is a complete, human-readable message.
#include <stdexcept>
#include <string>

namespace vkrt {

/// Where in a text file something is; line and column are 1-based, 0 = unknown.
struct SourceLocation {
    std::string file;
    int line = 0;
    int column = 0;

    /// "file:line:column" (or "file" when the position is unknown).
    std::string str() const
    {
        if (line <= 0) return file;
        return file + ":" + std::to_string(line) + ":" + std::to_string(column);
    }
};

/// A failure caused by the user's input (scene file, option, image file).
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A scene-file error; the message starts with "file:line:column: ".
class SceneError : public InputError {
public:
    SceneError(const SourceLocation& where, const std::string& message)
        : InputError(where.str() + ": " + message),
          m_where(where),
          m_message(message)
    {
    }
    const SourceLocation& where() const { return m_where; }
    /// The message without the location prefix.
    const std::string& message() const { return m_message; }

private:
    SourceLocation m_where;
    std::string m_message;
};

/// A failure of the GPU, the driver or the shader compiler.
class GpuError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Internal invariant violated: a bug in vkrt, never the user's fault.
class InternalError : public std::logic_error {
public:
    using std::logic_error::logic_error;
};

[[noreturn]] void failCheck(const char* expression, const char* file, int line);

/// Throws InputError("file: message"): what a reader says of a file it
/// cannot use where no line is known (binary formats, JSON documents).
[[noreturn]] void failInFile(const std::string& file, const std::string& message);

} // namespace vkrt

/// Checks an internal invariant; throws InternalError naming the source line.
#define VKRT_CHECK(cond) ((cond) ? (void)0 : ::vkrt::failCheck(#cond, __FILE__, __LINE__))
