// EXR headers are claims (issue 26, item 7): a header whose size, tiles or
// attributes the file cannot hold is refused before anything is allocated
// from it, with a message naming the file; real files of every compression,
// at their best compression, are still read.
#include "io/ExrFile.h"
#include "io/ImageHeader.h"
#include "support/TestSupport.h"
#include "texture/TextureTestFiles.h"
#include "util/Error.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <iterator>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

/// readExr's message for `path` (with `expected`), or "" when it reads it.
std::string refusal(const fs::path& path, const std::optional<ExpectedSize>& expected = {})
{
    try {
        readExr(path, expected);
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

std::string headerRefusal(const fs::path& path)
{
    try {
        readExrHeader(path);
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

/// A constant width x height float RGB image written with `compression`: the best any compression does.
fs::path writeConstantExr(const fs::path& path, int width, int height, Imf::Compression compression)
{
    std::vector<float> pixels(size_t(width) * height * 3, 0.25f);
    Imf::Header header(width, height);
    header.compression() = compression;
    Imf::FrameBuffer frame;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
        frame.insert(names[c],
                     Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data() + c), 12, 12 * size_t(width)));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(height);
    return path;
}

std::string fileBytes(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ExrBounds, HeadersClaimingHugeImagesAreRefusedAtOnceNamingTheFile)
{
    const fs::path dir = freshTempDir("exr-bounds-huge");
    const fs::path big = writeExrDeclaring(dir / "big.exr", 8192, 8192);
    const fs::path huge = writeExrDeclaring(dir / "huge.exr", 16384, 16384);
    const fs::path wide = writeExrDeclaring(dir / "wide.exr", 16385, 1);
    ASSERT_LT(fs::file_size(big), 6000u) << "a few hundred bytes claiming 768 MB of pixels";
    const auto start = std::chrono::steady_clock::now();
    EXPECT_NE(refusal(big).find(big.string() + ": the header declares 8192x8192 pixels of 3 channels (ZIP "
                                               "compression), which take at least "),
              std::string::npos)
        << refusal(big);
    EXPECT_NE(refusal(big).find("truncated or damaged"), std::string::npos) << refusal(big);
    EXPECT_NE(refusal(huge).find(huge.string() + ": the header declares 16384x16384 pixels; vkrt reads images of at "
                                                 "most 67108864 pixels"),
              std::string::npos)
        << refusal(huge);
    EXPECT_NE(refusal(wide).find("16385x1 pixels; vkrt reads images of at most 16384 pixels a side"), std::string::npos)
        << refusal(wide);
    for (const fs::path& path : {big, huge, wide}) EXPECT_EQ(headerRefusal(path), refusal(path));
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0)
        << "refused from the header, not after decoding";
}

TEST(ExrBounds, EveryCompressionAtItsBestStillReads)
{
    const fs::path dir = freshTempDir("exr-bounds-compressions");
    for (int c = 0; c < int(Imf::NUM_COMPRESSION_METHODS); ++c) {
        const auto compression = Imf::Compression(c);
        const fs::path path = writeConstantExr(dir / ("c" + std::to_string(c) + ".exr"), 2048, 512, compression);
        const double ratio = 2048.0 * 512 * 12 / double(fs::file_size(path));
        const double margin = compression == Imf::NO_COMPRESSION ? 1.0 : 1.5; // NONE's bound is exact
        EXPECT_LE(ratio * margin, double(exrMaxCompressionRatio(compression)))
            << "compression " << c << ": the bound keeps a margin over the best ratio measured";
        EXPECT_EQ(refusal(path), "") << "compression " << c;
    }
}

TEST(ExrBounds, AnUncompressedFileOneByteShortIsRefusedByItsLength)
{
    const fs::path dir = freshTempDir("exr-bounds-short");
    const fs::path path = writeConstantExr(dir / "a.exr", 64, 32, Imf::NO_COMPRESSION);
    ASSERT_EQ(refusal(path), "");
    fs::resize_file(path, fs::file_size(path) - 1);
    EXPECT_NE(refusal(path).find("take at least " + std::to_string(fs::file_size(path) + 1) +
                                 " bytes, but the file has " + std::to_string(fs::file_size(path))),
              std::string::npos)
        << refusal(path);
}

TEST(ExrBounds, ExpectedSizeIsCheckedFromTheHeader)
{
    const fs::path dir = freshTempDir("exr-bounds-expected");
    const fs::path path = writeConstantExr(dir / "a.exr", 16, 8, Imf::ZIP_COMPRESSION);
    EXPECT_EQ(refusal(path, ExpectedSize{16, 8, "the case renders"}), "");
    EXPECT_EQ(refusal(path, ExpectedSize{8, 16, "the case renders"}),
              path.string() + ": 16x8 pixels, but the case renders 8x16");
    // A huge claim with the wrong size is refused by the size before the length.
    const fs::path big = writeExrDeclaring(dir / "big.exr", 4096, 4096);
    EXPECT_NE(refusal(big, ExpectedSize{16, 8, "ref.exr is"}).find(big.string() + ": "), std::string::npos);
}

TEST(ExrBounds, AttributeSizeBeyondTheFileIsRefusedBeforeOpenExrAllocatesIt)
{
    const fs::path dir = freshTempDir("exr-bounds-attribute");
    Metadata metadata{{"note", std::string("short")}};
    writeExr(dir / "a.exr", Image(4, 4), metadata);
    std::string bytes = fileBytes(dir / "a.exr");
    const std::string key("note\0string\0", 12);
    const size_t at = bytes.find(key);
    ASSERT_NE(at, std::string::npos);
    const int32_t size = 0x7fffffff; // OpenEXR would resize a string to 2 GiB before reading it
    std::memcpy(&bytes[at + key.size()], &size, 4);
    writeBytes(dir / "a.exr", bytes);
    EXPECT_NE(refusal(dir / "a.exr").find("header attribute 'note' declares 2147483647 bytes, but the file has"),
              std::string::npos)
        << refusal(dir / "a.exr");
}

TEST(ExrBounds, TilesTheFileCannotHoldAreRefused)
{
    const fs::path dir = freshTempDir("exr-bounds-tiles");
    auto writeTiled = [&](const std::string& name, int side, int tile) {
        Imf::Header header(side, side);
        header.setTileDescription(Imf::TileDescription(tile, tile, Imf::ONE_LEVEL));
        header.channels().insert("R", Imf::Channel(Imf::FLOAT));
        header.channels().insert("G", Imf::Channel(Imf::FLOAT));
        header.channels().insert("B", Imf::Channel(Imf::FLOAT));
        std::vector<float> pixels(size_t(side) * side * 3, 1.0f);
        Imf::FrameBuffer frame;
        for (int c = 0; c < 3; ++c)
            frame.insert(std::string(1, "RGB"[c]),
                         Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data() + c), 12, 12 * size_t(side)));
        Imf::TiledOutputFile file((dir / name).c_str(), header);
        file.setFrameBuffer(frame);
        file.writeTiles(0, file.numXTiles() - 1, 0, file.numYTiles() - 1);
        return dir / name;
    };
    const fs::path fine = writeTiled("fine.exr", 64, 16);
    EXPECT_EQ(refusal(fine), "");
    // 1x1 tiles claimed for 4096x4096: 16 Mi chunks, an offset table of 128 MiB.
    std::string bytes = fileBytes(writeTiled("ones.exr", 4, 1));
    const std::string key("dataWindow\0box2i\0", 17);
    const int32_t window[4] = {0, 0, 4095, 4095};
    std::memcpy(&bytes[bytes.find(key) + key.size() + 4], window, sizeof window);
    writeBytes(dir / "ones.exr", bytes);
    EXPECT_NE(refusal(dir / "ones.exr").find("the header declares 4096x4096 pixels"), std::string::npos)
        << refusal(dir / "ones.exr");
    const fs::path wideTiles = writeTiled("wide-tiles.exr", 8, 1024);
    EXPECT_NE(refusal(wideTiles).find("1024x1024 tiles for a 8x8 image"), std::string::npos) << refusal(wideTiles);
}

TEST(ExrBounds, ImageFileExtentReadsHeadersOnly)
{
    const fs::path dir = freshTempDir("exr-bounds-extent");
    EXPECT_EQ(imageFileExtent(writeConstantExr(dir / "a.EXR", 24, 12, Imf::PIZ_COMPRESSION)).str(), "24x12");
    EXPECT_EQ(imageFileExtent(writePngBomb(dir / "bomb.png", 16384)).str(), "16384x16384");
    EXPECT_LT(fs::file_size(dir / "bomb.png"), uint64_t(2) << 20);
    EXPECT_THROW(imageFileExtent(dir / "missing.png"), InputError);
    EXPECT_THROW(imageFileExtent(writeExrDeclaring(dir / "big.exr", 8192, 8192)), InputError);
}

} // namespace
} // namespace vkrt::test
