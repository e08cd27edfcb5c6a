#include "render/ConvergenceReport.h"

#include "io/AtomicFile.h"

#include <cstdio>

namespace vkrt {

ConvergenceReport::ConvergenceReport(std::filesystem::path path, std::string header, std::optional<Image> reference)
    : m_path(std::move(path)),
      m_header(std::move(header)),
      m_reference(std::move(reference))
{
}

void ConvergenceReport::add(uint32_t spp, double renderSeconds, const Image& mean, const EstimatedError& estimated)
{
    ConvergenceRow row{spp, renderSeconds, estimated, std::nullopt};
    if (m_reference) row.measured = measureError(mean, *m_reference);
    m_rows.push_back(row);
    // Whole-buffer write: every write, the flush and the close are checked, so a full disk keeps the old report.
    writeBytesAtomically(m_path, text());
}

std::string ConvergenceReport::text() const
{
    std::string csv = "# " + m_header + "\n";
    csv += "spp,seconds,est_rmse,est_relmse,est_relmse_upper,est_dof";
    csv += m_reference ? ",rmse,relmse,mape\n" : "\n";
    for (const ConvergenceRow& r : m_rows) {
        char line[256];
        int n =
            std::snprintf(line, sizeof line, "%u,%.6f,%.9g,%.9g,%.9g,%.6g", r.spp, r.renderSeconds, r.estimated.rmse,
                          r.estimated.relMse, r.estimated.relMseUpper, r.estimated.degreesOfFreedom);
        if (r.measured)
            std::snprintf(line + n, sizeof line - size_t(n), ",%.9g,%.9g,%.9g", r.measured->rmse, r.measured->relMse,
                          r.measured->mape);
        csv += std::string(line) + "\n";
    }
    return csv;
}

} // namespace vkrt
