#pragma once
// The CSV written by `vkrt render --report`: one row per checkpoint (1, 2, 4,
// ... spp and the last) with render seconds and estimated error, plus the
// true error when a reference image is given. Formulas: docs/convergence.md.
#include "io/Image.h"
#include "render/ErrorMetrics.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

struct ConvergenceRow {
    uint32_t spp = 0;
    double renderSeconds = 0.0;
    EstimatedError estimated;
    std::optional<MeasuredError> measured;
};

class ConvergenceReport {
public:
    /// `header`: one line of context (scene, device, start-up seconds), written as a # comment.
    ConvergenceReport(std::filesystem::path path, std::string header, std::optional<Image> reference);

    /// Adds a row for the current image and rewrites the file atomically, so
    /// the file on disk is always complete.
    void add(uint32_t spp, double renderSeconds, const Image& mean, const EstimatedError& estimated);

    const std::vector<ConvergenceRow>& rows() const { return m_rows; }
    /// The CSV text (header comment, column names, rows).
    std::string text() const;

private:
    std::filesystem::path m_path;
    std::string m_header;
    std::optional<Image> m_reference;
    std::vector<ConvergenceRow> m_rows;
};

} // namespace vkrt
