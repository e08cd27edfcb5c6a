// EXR and PNG output: round trips, metadata, clear errors, atomic writes.
#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "support/TestSupport.h"

#include <cmath>
#include <fstream>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

Image gradient(uint32_t w, uint32_t h)
{
    Image image(w, h);
    for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = float(i) * 0.37f - 3.0f;
    image.rgb[5] = 1e30f;  // HDR values survive
    image.rgb[6] = 1e-40f; // so do denormals
    return image;
}

TEST(ExrFile, RoundTripsPixelsLayersAndMetadataExactly)
{
    fs::path dir = freshTempDir("exr-roundtrip");
    Image image = gradient(7, 5), variance = gradient(7, 5);
    variance.rgb[0] = 42.0f;
    Metadata metadata{{"spp", int64_t(64)}, {"big", int64_t(1) << 40}, {"seconds", 1.25}, {"device", std::string("x")}};
    writeExr(dir / "a.exr", image, metadata, {{"variance", variance}});
    ExrContents back = readExr(dir / "a.exr");
    EXPECT_EQ(back.image.width, 7u);
    EXPECT_EQ(back.image.height, 5u);
    EXPECT_EQ(back.image.rgb, image.rgb);
    ASSERT_TRUE(back.layers.count("variance"));
    EXPECT_EQ(back.layers["variance"].rgb, variance.rgb);
    EXPECT_EQ(std::get<int64_t>(back.metadata.at("spp")), 64);
    EXPECT_EQ(std::get<double>(back.metadata.at("big")), double(int64_t(1) << 40));
    EXPECT_EQ(std::get<double>(back.metadata.at("seconds")), 1.25);
    EXPECT_EQ(std::get<std::string>(back.metadata.at("device")), "x");
}

TEST(ExrFile, DamagedOrMissingFilesGiveErrorsNamingThePath)
{
    fs::path dir = freshTempDir("exr-bad");
    writeText(dir / "junk.exr", "this is not an EXR file");
    for (const fs::path& path : {dir / "junk.exr", dir / "missing.exr"}) {
        try {
            readExr(path);
            FAIL() << "expected InputError for " << path;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
        }
    }
}

TEST(ExrFile, TruncatedFileIsAnError)
{
    fs::path dir = freshTempDir("exr-truncated");
    writeExr(dir / "a.exr", gradient(64, 64), {});
    auto size = fs::file_size(dir / "a.exr");
    fs::resize_file(dir / "a.exr", size / 2);
    EXPECT_THROW(readExr(dir / "a.exr"), InputError);
}

TEST(AtomicWrite, FailedWriteLeavesNoFileAndKeepsTheOldOne)
{
    fs::path dir = freshTempDir("atomic");
    writeText(dir / "out.exr", "old");
    auto failHalfWay = [](const fs::path& temporary) {
        writeText(temporary, "half of a file");
        throw InputError("disk full");
    };
    EXPECT_THROW(writeFileAtomically(dir / "out.exr", failHalfWay), InputError);
    std::ifstream in(dir / "out.exr");
    std::string contents((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(contents, "old");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(AtomicWrite, MissingDirectoryIsAnErrorNamingIt)
{
    try {
        writeExr("/nonexistent-dir/out.exr", Image(2, 2), {});
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent-dir"), std::string::npos) << e.what();
    }
}

TEST(ToneMap, SrgbEncodingOfKnownValues)
{
    EXPECT_EQ(toneMapToSrgb8(0.0f, 0.0f), 0);
    EXPECT_EQ(toneMapToSrgb8(1.0f, 0.0f), 255);
    EXPECT_EQ(toneMapToSrgb8(5.0f, 0.0f), 255);
    EXPECT_EQ(toneMapToSrgb8(-1.0f, 0.0f), 0);
    EXPECT_EQ(toneMapToSrgb8(std::nanf(""), 0.0f), 0);
    EXPECT_EQ(toneMapToSrgb8(0.18f, 0.0f), 118);        // 18 % grey
    EXPECT_EQ(toneMapToSrgb8(0.25f, 0.0f), 137);        // 1.055 * 0.25^(1/2.4) - 0.055 = 0.5371
    EXPECT_EQ(toneMapToSrgb8(0.125f, 1.0f), 137);       // one stop up doubles it
    EXPECT_EQ(toneMapToSrgb8(0.0031308f / 2, 0.0f), 5); // linear segment: 12.92 * x
}

TEST(PngFile, WritesAValidPngSignature)
{
    fs::path dir = freshTempDir("png");
    writePng(dir / "a.png", gradient(8, 8), 0.0f);
    std::ifstream in(dir / "a.png", std::ios::binary);
    char signature[8];
    in.read(signature, 8);
    EXPECT_EQ(std::string(signature + 1, 3), "PNG");
}

} // namespace
} // namespace vkrt::test
