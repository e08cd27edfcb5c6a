#pragma once
// Output files appear whole or not at all: write to a temporary file beside the
// target, flush it to disk, then rename it over the target (atomic within one
// file system). What vkrt does with what already is at an output path:
//  - nothing: a new file, mode 0666 & ~umask like any program's;
//  - a regular file: replaced; its permission bits are kept, and its owner and
//    group too when vkrt runs as root (other hard links keep the old contents);
//  - a symbolic link (or a chain of them): the file it points to is written,
//    atomically, through a temporary beside that file; the link stays a link;
//  - /dev/null: the output is discarded (nothing is encoded or written);
//  - a directory, device, FIFO or socket: refused with an InputError, since
//    writing one through a temporary and a rename would replace it.
// A temporary exists only while it is written; SIGINT, SIGTERM and SIGHUP
// remove it (util/Signals.h) and any error removes it and keeps the old file.
#include <filesystem>
#include <functional>
#include <string_view>

namespace vkrt {

/// What writing to a path will do.
enum class OutputTargetKind { NewFile, ExistingFile, Discarded };

struct OutputTarget {
    std::filesystem::path path; ///< the file written: the given path with symbolic links followed
    OutputTargetKind kind = OutputTargetKind::NewFile;
};

/// Follows symbolic links from `path` and decides as above; throws InputError
/// naming `path` for a refused kind of file or a missing directory.
OutputTarget resolveOutputTarget(const std::filesystem::path& path);

/// Calls write(temporaryPath) and renames the result to `path`. If `write`
/// throws, the temporary is removed and the exception propagates; an existing
/// file at `path` is left untouched. `write` must check its own writes (a
/// std::ofstream must be closed and checked). Throws InputError naming `path`
/// on failure.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path&)>& write);

/// Writes `bytes` to `path` atomically with every write, the flush to disk and
/// the close checked: a full disk is an InputError and the old file stays.
void writeBytesAtomically(const std::filesystem::path& path, std::string_view bytes);

} // namespace vkrt
