#include "support/ChiSquare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace vkrt::test {
namespace {

/// Series for the lower regularized gamma P(a, x), good for x < a + 1.
double lowerGammaSeries(double a, double x)
{
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000; ++n) {
        term *= x / (a + n);
        sum += term;
        if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

/// Continued fraction for Q(a, x) (modified Lentz), good for x >= a + 1.
double upperGammaContinuedFraction(double a, double x)
{
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1.0) < 1e-16) break;
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

/// 3 x 3 Simpson on a rectangle.
double simpson9(const std::function<double(double, double)>& f, double u0, double u1, double v0, double v1)
{
    double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
    double sum = f(u0, v0) + f(u1, v0) + f(u0, v1) + f(u1, v1)
               + 4.0 * (f(um, v0) + f(um, v1) + f(u0, vm) + f(u1, vm)) + 16.0 * f(um, vm);
    return sum * (u1 - u0) * (v1 - v0) / 36.0;
}

double refine(const std::function<double(double, double)>& f, double u0, double u1, double v0, double v1,
              double whole, double tolerance, int depth)
{
    double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1);
    double q[4] = {simpson9(f, u0, um, v0, vm), simpson9(f, um, u1, v0, vm), simpson9(f, u0, um, vm, v1),
                   simpson9(f, um, u1, vm, v1)};
    double parts = q[0] + q[1] + q[2] + q[3];
    if (depth <= 0 || std::abs(parts - whole) <= 15.0 * tolerance) return parts + (parts - whole) / 15.0;
    // Half (not a quarter) of the tolerance per child: errors of the four children rarely add up, and
    // the stricter split makes smooth lobes refine several levels deeper for nothing.
    return refine(f, u0, um, v0, vm, q[0], 0.5 * tolerance, depth - 1)
         + refine(f, um, u1, v0, vm, q[1], 0.5 * tolerance, depth - 1)
         + refine(f, u0, um, vm, v1, q[2], 0.5 * tolerance, depth - 1)
         + refine(f, um, u1, vm, v1, q[3], 0.5 * tolerance, depth - 1);
}

struct Cell {
    double expected = 0.0;
    double observed = 0.0;
    int index = -1; ///< -1: the cell of rejected samples
};

std::string describeCell(const Cell& cell, int thetaBins, int phiBins)
{
    char line[160];
    if (cell.index < 0) {
        std::snprintf(line, sizeof line, "  rejected samples             observed %10.0f expected %12.2f\n",
                      cell.observed, cell.expected);
        return line;
    }
    int i = cell.index / phiBins, j = cell.index % phiBins;
    double c0 = -1.0 + 2.0 * i / thetaBins, c1 = -1.0 + 2.0 * (i + 1) / thetaBins;
    double p0 = 360.0 * j / phiBins, p1 = 360.0 * (j + 1) / phiBins;
    std::snprintf(line, sizeof line, "  cos [%+.3f, %+.3f] phi [%5.1f, %5.1f] observed %10.0f expected %12.2f\n", c0,
                  c1, p0, p1, cell.observed, cell.expected);
    return line;
}

} // namespace

double integrate2d(const std::function<double(double, double)>& f, double u0, double u1, double v0, double v1,
                   int n, double tolerance)
{
    double sum = 0.0, du = (u1 - u0) / n, dv = (v1 - v0) / n;
    double panelTolerance = tolerance / (n * n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            double a0 = u0 + i * du, a1 = a0 + du, b0 = v0 + j * dv, b1 = b0 + dv;
            sum += refine(f, a0, a1, b0, b1, simpson9(f, a0, a1, b0, b1), panelTolerance, 10);
        }
    return sum;
}

double upperIncompleteGammaQ(double a, double x)
{
    if (!(a > 0.0) || !(x >= 0.0)) throw std::invalid_argument("upperIncompleteGammaQ: needs a > 0, x >= 0");
    if (x == 0.0) return 1.0;
    if (x < a + 1.0) return 1.0 - lowerGammaSeries(a, x);
    return upperGammaContinuedFraction(a, x);
}

double chiSquarePValue(double statistic, int degreesOfFreedom)
{
    if (degreesOfFreedom <= 0) return 1.0;
    return upperIncompleteGammaQ(0.5 * degreesOfFreedom, 0.5 * std::max(0.0, statistic));
}

double sidakCorrectedAlpha(double alpha, int tests)
{
    return 1.0 - std::pow(1.0 - alpha, 1.0 / std::max(1, tests));
}

ChiSquareResult chiSquareTest(std::span<const glm::dvec3> samples, long long rejected, const DirectionPdf& pdf,
                              const ChiSquareOptions& options)
{
    const int thetaBins = options.thetaBins, phiBins = 2 * options.thetaBins;
    const double total = double(samples.size()) + double(rejected);
    std::vector<Cell> cells(size_t(thetaBins) * phiBins);
    for (size_t c = 0; c < cells.size(); ++c) cells[c].index = int(c);

    // Observed counts.
    for (const glm::dvec3& w : samples) {
        double cosTheta = std::clamp(w.z, -1.0, 1.0);
        double phi = std::atan2(w.y, w.x);
        if (phi < 0.0) phi += 2.0 * std::numbers::pi;
        int i = std::min(thetaBins - 1, int((cosTheta + 1.0) * 0.5 * thetaBins));
        int j = std::min(phiBins - 1, int(phi / (2.0 * std::numbers::pi) * phiBins));
        cells[size_t(i) * phiBins + j].observed += 1.0;
    }
    // Expected counts: the pdf integrated over each cell in (theta, phi), dw = sin(theta) dtheta dphi. Not in
    // cos(theta): a lobe around the pole is smooth in theta but has a square-root profile in cos(theta),
    // which adaptive Simpson refines without end.
    auto density = [&](double theta, double phi) {
        double sinTheta = std::sin(theta);
        return pdf(glm::dvec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), std::cos(theta))) * sinTheta;
    };
    ChiSquareResult result;
    for (int i = 0; i < thetaBins; ++i)
        for (int j = 0; j < phiBins; ++j) {
            double c0 = -1.0 + 2.0 * i / thetaBins, c1 = -1.0 + 2.0 * (i + 1) / thetaBins;
            double p0 = 2.0 * std::numbers::pi * j / phiBins, p1 = 2.0 * std::numbers::pi * (j + 1) / phiBins;
            double mass = integrate2d(density, std::acos(c1), std::acos(c0), p0, p1, options.subCells,
                                      options.countTolerance / total);
            cells[size_t(i) * phiBins + j].expected = total * mass;
            result.integratedPdf += mass;
        }
    // The rejected draws form one more cell, expecting the probability the pdf does not cover.
    Cell rejectedCell{total * std::max(0.0, 1.0 - result.integratedPdf), double(rejected), -1};
    if (rejected > 0 || rejectedCell.expected > 1e-3 * total / double(cells.size())) cells.push_back(rejectedCell);

    // Contributions per cell; a sample where nothing is expected fails the test outright.
    std::vector<std::pair<double, Cell>> contributions;
    for (const Cell& cell : cells)
        if (cell.expected <= 0.0 && cell.observed > 0.0) {
            contributions.push_back({INFINITY, cell});
            result.statistic = INFINITY;
        }
    // Pool small cells in increasing order of expected count until each pool expects minExpected.
    std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.expected < b.expected; });
    Cell pool{0.0, 0.0, -2};
    int bins = 0;
    for (const Cell& cell : cells) {
        if (cell.expected <= 0.0) continue;
        if (cell.expected < options.minExpected) {
            pool.expected += cell.expected;
            pool.observed += cell.observed;
            if (pool.expected < options.minExpected) continue;
            double d = pool.observed - pool.expected;
            result.statistic += d * d / pool.expected;
            pool = {0.0, 0.0, -2};
        } else {
            double d = cell.observed - cell.expected;
            result.statistic += d * d / cell.expected;
            contributions.push_back({d * d / cell.expected, cell});
        }
        ++bins;
    }
    if (pool.expected > 0.0) { // a last, small pool
        double d = pool.observed - pool.expected;
        result.statistic += d * d / pool.expected;
        ++bins;
    }
    result.degreesOfFreedom = bins - 1;
    result.pValue = std::isinf(result.statistic) ? 0.0 : chiSquarePValue(result.statistic, result.degreesOfFreedom);

    // The table: cells that contributed most.
    std::sort(contributions.begin(), contributions.end(), [](auto& a, auto& b) { return a.first > b.first; });
    char head[200];
    std::snprintf(head, sizeof head, "chi2 = %.2f, dof = %d, p = %.3g, pdf integral = %.6f, %zu + %lld samples\n",
                  result.statistic, result.degreesOfFreedom, result.pValue, result.integratedPdf, samples.size(),
                  rejected);
    result.table = head;
    for (int k = 0; k < std::min<int>(options.worstCellsShown, int(contributions.size())); ++k)
        result.table += describeCell(contributions[k].second, thetaBins, phiBins);
    return result;
}

ChiSquareResult chiSquareTest(std::span<const glm::vec3> samples, long long rejected, const DirectionPdf& pdf,
                              const ChiSquareOptions& options)
{
    std::vector<glm::dvec3> directions(samples.begin(), samples.end());
    return chiSquareTest(std::span<const glm::dvec3>(directions), rejected, pdf, options);
}

} // namespace vkrt::test
