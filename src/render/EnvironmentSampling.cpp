#include "render/EnvironmentSampling.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vkrt {

bool isConstantEnvironment(std::span<const Image> images)
{
    const float* first = nullptr;
    for (const Image& image : images) {
        for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
            if (!first) first = &image.rgb[i];
            else if (!std::equal(first, first + 3, &image.rgb[i])) return false;
        }
    }
    return true;
}

std::vector<float> environmentCdf(const std::array<Image, 6>& faces)
{
    const uint32_t n = faces[0].width;
    std::vector<double> weights;
    weights.reserve(6 * size_t(n) * n);
    for (const Image& face : faces) {
        for (uint32_t y = 0; y < n; ++y) {
            for (uint32_t x = 0; x < n; ++x) {
                const float* t = face.at(x, y);
                double luminance = 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
                double sc = 2.0 * (x + 0.5) / n - 1.0, tc = 2.0 * (y + 0.5) / n - 1.0;
                double r = std::sqrt(sc * sc + tc * tc + 1.0);
                weights.push_back(std::max(0.0, luminance) / (r * r * r));
            }
        }
    }
    double total = 0.0;
    for (double w : weights) total += w;
    if (!(total > 0.0)) {
        weights.assign(weights.size(), 1.0);
        total = double(weights.size());
    }
    std::vector<float> cdf(weights.size() + 1, 0.0f);
    double running = 0.0;
    for (size_t i = 0; i < weights.size(); ++i) {
        running += weights[i];
        cdf[i + 1] = float(running / total);
    }
    cdf.back() = 1.0f;
    return cdf;
}

namespace {

double luminance(const float* t) { return std::max(0.0, 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2]); }

uint32_t blockFor(uint32_t cellColumns, uint32_t cellRows)
{
    uint32_t block = 1;
    auto cells = [&] { return uint64_t((cellColumns + block - 1) / block) * ((cellRows + block - 1) / block); };
    while (cells() > kMaxLatLongCells) block *= 2;
    return block;
}

/// Each bilinear cell's weight, row-major (W columns, H - 1 rows).
std::vector<double> bilinearCellWeights(const Image& map)
{
    const uint32_t w = map.width, rows = map.height - 1;
    std::vector<double> weights(size_t(w) * rows);
    for (uint32_t j = 0; j < rows; ++j) {
        const double sinTheta = std::sin(std::numbers::pi * (j + 0.5) / rows);
        for (uint32_t i = 0; i < w; ++i) {
            const uint32_t next = (i + 1) % w;
            const double mean = 0.25 * (luminance(map.at(i, j)) + luminance(map.at(next, j)) +
                                        luminance(map.at(i, j + 1)) + luminance(map.at(next, j + 1)));
            weights[size_t(j) * w + i] = mean * sinTheta;
        }
    }
    return weights;
}

/// Cumulative sums of `weights` from 0 to exactly 1 appended to `cdf`
/// (uniform when they are all zero); returns their total.
double appendCdf(const std::vector<double>& weights, std::vector<float>& cdf)
{
    double total = 0.0;
    for (double w : weights) total += w;
    const bool uniform = !(total > 0.0);
    cdf.push_back(0.0f);
    double running = 0.0;
    for (size_t i = 0; i < weights.size(); ++i) {
        running += uniform ? 1.0 : weights[i];
        cdf.push_back(float(running / (uniform ? double(weights.size()) : total)));
    }
    cdf.back() = 1.0f;
    return total;
}

} // namespace

LatLongDistribution latLongDistribution(const Image& map)
{
    const uint32_t w = map.width, cellRows = map.height - 1;
    LatLongDistribution d;
    d.block = blockFor(w, cellRows);
    d.columns = (w + d.block - 1) / d.block;
    d.rows = (cellRows + d.block - 1) / d.block;
    const std::vector<double> cells = bilinearCellWeights(map);
    // Grid cells' weights, row by row.
    std::vector<std::vector<double>> grid(d.rows, std::vector<double>(d.columns, 0.0));
    for (uint32_t j = 0; j < cellRows; ++j)
        for (uint32_t i = 0; i < w; ++i) grid[j / d.block][i / d.block] += cells[size_t(j) * w + i];
    std::vector<double> rowWeights(d.rows, 0.0);
    std::vector<float> rowsCdf;
    rowsCdf.reserve(size_t(d.rows) * (d.columns + 1));
    for (uint32_t b = 0; b < d.rows; ++b) rowWeights[b] = appendCdf(grid[b], rowsCdf);
    // A row whose cells are all black is never drawn, but keeps a valid (uniform) conditional CDF.
    d.cdf.reserve(d.rows + 1 + rowsCdf.size());
    appendCdf(rowWeights, d.cdf);
    d.cdf.insert(d.cdf.end(), rowsCdf.begin(), rowsCdf.end());
    return d;
}

} // namespace vkrt
