// `vkrt compare A.exr B.exr`: error measures between two images, and with
// variances a per-pixel statistical test; a threshold exceeded is a Failed
// outcome (exit 4) so scripts and CI can rely on it.
#include "app/Commands.h"
#include "app/ExitCodes.h"
#include "io/ExrFile.h"
#include "render/ErrorMetrics.h"
#include "render/Outcome.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <variant>
#include <vector>

namespace vkrt {

namespace {

struct CompareOptions {
    std::string a, b;
    std::string varianceA, varianceB;
    std::optional<double> maxRmse, maxRelMse;
    double alpha = 0.01;
    double minPass = 0.9975;
};

/// A variance image and the degrees of freedom it was estimated with.
struct VarianceImage {
    Image image;
    double degreesOfFreedom = INFINITY; ///< unknown: treated as exact (a Z-test)
};

/// vkrt's "varianceDegreesOfFreedom" attribute, when the file has one; a
/// value below 1 (no estimate was made) or of another type is an error, never
/// a test that silently passes or silently becomes a Z-test.
double degreesOfFreedomOf(const ExrContents& exr, const std::string& path)
{
    auto it = exr.metadata.find("varianceDegreesOfFreedom");
    if (it == exr.metadata.end()) return INFINITY;
    double dof = NAN;
    if (std::holds_alternative<int64_t>(it->second)) dof = double(std::get<int64_t>(it->second));
    else if (std::holds_alternative<double>(it->second)) dof = std::get<double>(it->second);
    if (!(dof >= 1.0) || !std::isfinite(dof))
        throw InputError(path + ": attribute varianceDegreesOfFreedom must be a number of at least 1" +
                         (dof == 0.0 ? " (0: the render had too few samples for an error estimate)" : ""));
    return dof;
}

/// The variance image for one side: an explicit file, else the image's own
/// "variance" layer, else none.
std::optional<VarianceImage> varianceFor(const std::string& explicitPath, const ExrContents& image,
                                         const std::string& imagePath, const Image& shape, const char* option)
{
    std::optional<VarianceImage> variance;
    if (!explicitPath.empty()) {
        ExrContents file =
            readExr(explicitPath, ExpectedSize{shape.width, shape.height, std::string(option) + "'s image is"});
        variance = VarianceImage{file.image, degreesOfFreedomOf(file, explicitPath)};
    } else if (image.layers.count("variance")) {
        variance = VarianceImage{image.layers.at("variance"), degreesOfFreedomOf(image, imagePath)};
    }
    if (variance && (variance->image.width != shape.width || variance->image.height != shape.height))
        throw InputError(std::string(option) + " " + explicitPath + ": variance is " +
                         std::to_string(variance->image.width) + "x" + std::to_string(variance->image.height) +
                         ", the image is " + std::to_string(shape.width) + "x" + std::to_string(shape.height));
    return variance;
}

/// B (and any variance file) must have A's size. Both headers are read
/// first: a size that differs, or a header that claims more pixels than its
/// file holds, is refused before either image is allocated.
ExpectedSize sizeOfA(const CompareOptions& o)
{
    const ExrHeader a = readExrHeader(o.a);
    readExrHeader(o.b, ExpectedSize{a.width, a.height, o.a + " is"});
    return {a.width, a.height, o.a + " is"};
}

/// The FAIL lines go to stdout with the measures above them, so the outcome
/// carries no messages of its own.
Outcome runCompare(const CompareOptions& o)
{
    const ExpectedSize size = sizeOfA(o);
    ExrContents a = readExr(o.a, size), b = readExr(o.b, size);
    std::optional<VarianceImage> va = varianceFor(o.varianceA, a, o.a, a.image, "--variance-a");
    std::optional<VarianceImage> vb = varianceFor(o.varianceB, b, o.b, b.image, "--variance-b");

    MeasuredError e = measureError(a.image, b.image);
    std::printf("A: %s\nB: %s (reference for relMSE and MAPE)\n", o.a.c_str(), o.b.c_str());
    std::printf("size        %ux%u\n", a.image.width, a.image.height);
    std::printf("RMSE        %.6g\nrelMSE      %.6g\nMAPE        %.6g\nmax |A-B|   %.6g\n", e.rmse, e.relMse, e.mape,
                e.maxAbs);
    std::printf("non-finite  A: %zu  B: %zu\n", e.nonFiniteA, e.nonFiniteB);

    std::vector<std::string> failures;
    if (e.nonFiniteA || e.nonFiniteB) failures.push_back("non-finite values");
    if (o.maxRmse && !(e.rmse <= *o.maxRmse))
        failures.push_back("RMSE exceeds --max-rmse " + std::to_string(*o.maxRmse));
    if (o.maxRelMse && !(e.relMse <= *o.maxRelMse))
        failures.push_back("relMSE exceeds --max-relmse " + std::to_string(*o.maxRelMse));
    if (va || vb) {
        VarianceImage zero{Image(a.image.width, a.image.height)};
        const VarianceImage& varA = va ? *va : zero;
        const VarianceImage& varB = vb ? *vb : zero;
        PixelTestSummary t =
            pixelZTest(a.image, varA.image, b.image, varB.image, o.alpha, varA.degreesOfFreedom, varB.degreesOfFreedom);
        bool welch = std::isfinite(varA.degreesOfFreedom) || std::isfinite(varB.degreesOfFreedom);
        std::printf("pixel test  %zu of %zu values pass (%.4f%%), p >= %.3g (alpha %.3g, Sidak; %s); smallest p %.3g\n",
                    t.passed, t.tested, 100.0 * t.fractionPassed(), t.threshold, o.alpha,
                    welch ? "Welch's t from the variances' degrees of freedom" : "Z-test", t.minPValue);
        if (t.fractionPassed() < o.minPass)
            failures.push_back("fewer than " + std::to_string(100.0 * o.minPass) + "% of values pass the pixel test");
    }
    for (const auto& f : failures) std::printf("FAIL: %s\n", f.c_str());
    if (failures.empty()) std::printf("OK\n");
    return failures.empty() ? Outcome::passed() : Outcome::of(OutcomeKind::Failed);
}

} // namespace

CommandRunner addCompareCommand(CLI::App& app)
{
    auto o = std::make_shared<CompareOptions>();
    CLI::App* cmd = app.add_subcommand("compare", "Compare two EXR images (error measures and a per-pixel test)");
    cmd->add_option("a", o->a, "Image A (EXR)")->required();
    cmd->add_option("b", o->b, "Image B, the reference (EXR)")->required();
    cmd->add_option("--variance-a", o->varianceA, "Variance of A's pixel means (default: A's 'variance' layer)");
    cmd->add_option("--variance-b", o->varianceB, "Variance of B's pixel means (default: B's 'variance' layer)");
    cmd->add_option("--max-rmse", o->maxRmse, "Fail when the RMSE exceeds this")->check(CLI::NonNegativeNumber);
    cmd->add_option("--max-relmse", o->maxRelMse, "Fail when the relMSE exceeds this")->check(CLI::NonNegativeNumber);
    cmd->add_option("--alpha", o->alpha, "Significance of the pixel test over all values")
        ->check(CLI::Range(1e-12, 0.5));
    cmd->add_option("--min-pass", o->minPass, "Fraction of values that must pass the pixel test")
        ->check(CLI::Range(0.0, 1.0));
    return [o] { return exitCodeFor(runCompare(*o)); };
}

} // namespace vkrt
