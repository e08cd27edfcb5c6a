// Issue 26, outputs and signals: an output never destroys an input, a device,
// a link or a file's mode; every write is whole or reported; a signal leaves no
// temporary behind; a second Ctrl-C and a crashing driver end vkrt clearly.
#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "support/TestSupport.h"
#include "util/Error.h"
#include "util/Signals.h"

#include <chrono>
#include <csignal>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

// ---------------------------------------------------------------- helpers

const char* kSphereScene = R"([camera]
eye = [0.0, 0.0, 4.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40
width = 32
height = 24

[materials.white]
type = "lambert"
albedo = [0.8, 0.8, 0.8]

[[objects]]
shape = "sphere"
material = "white"
center = [0.0, 0.0, 0.0]
radius = 1.0

[background]
color = [0.6, 0.75, 1.0]
)";

std::string readAll(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// Names in `dir` that look like vkrt's temporaries (".NAME.tmp-PID-RAND.ext").
std::vector<std::string> temporariesIn(const fs::path& dir)
{
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(dir))
        if (contains(entry.path().filename().string(), ".tmp-")) found.push_back(entry.path().filename().string());
    return found;
}

std::vector<std::string> deviceArgs()
{
    const char* device = std::getenv("VKRT_TEST_DEVICE");
    return device ? std::vector<std::string>{"--device", device} : std::vector<std::string>{};
}

/// A vkrt process started without waiting, its output going to a file.
struct RunningVkrt {
    pid_t pid = -1;
    fs::path log;
    std::optional<int> status; ///< the wait status, once it ended

    bool running()
    {
        int s = 0;
        if (!status && waitpid(pid, &s, WNOHANG) == pid) status = s;
        return !status;
    }
    /// Waits at most `limit`; returns the wait status, or nullopt (and kills it) past the limit.
    std::optional<int> waitFor(std::chrono::seconds limit)
    {
        const auto end = std::chrono::steady_clock::now() + limit;
        while (running() && std::chrono::steady_clock::now() < end)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        if (status) return status;
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
        return std::nullopt;
    }
    std::string output() const { return readAll(log); }
};

RunningVkrt startVkrt(const std::vector<std::string>& args, const fs::path& log,
                      const std::vector<std::pair<std::string, std::string>>& environment = {})
{
    RunningVkrt run{fork(), log, std::nullopt};
    if (run.pid == 0) {
        for (const auto& [name, value] : environment) setenv(name.c_str(), value.c_str(), 1);
        const int out = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, STDOUT_FILENO);
        dup2(out, STDERR_FILENO);
        std::vector<char*> argv{const_cast<char*>(VKRT_BINARY)};
        for (const auto& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
        argv.push_back(nullptr);
        execv(VKRT_BINARY, argv.data());
        _exit(127);
    }
    return run;
}

class OutputSafety : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = freshTempDir(std::string("output-safety-") +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
        m_scene = m_dir / "scene.toml";
        writeText(m_scene, kSphereScene);
    }

    ProcessResult render(std::vector<std::string> extra)
    {
        std::vector<std::string> args = {"render", m_scene.string(), "--spp", "1"};
        args.insert(args.end(), extra.begin(), extra.end());
        for (const std::string& a : deviceArgs()) args.push_back(a);
        return runVkrt(args);
    }

    fs::path m_dir;
    fs::path m_scene;
};

// ---------------------------------------------------------------- 2: an output equal to an input

TEST_F(OutputSafety, RenderRefusesAnOutputThatIsAnInputOrAnotherOutput)
{
    const std::string scene = readAll(m_scene);
    const fs::path exr = m_dir / "out.exr";
    fs::create_hard_link(m_scene, m_dir / "hardlink.toml");
    fs::create_symlink(m_scene, m_dir / "symlink.png");
    struct Case {
        std::vector<std::string> args;
        std::string expected;
    } cases[] = {
        {{"-o", m_scene.string()}, m_scene.string() + ": -o is the same file as the scene file"},
        {{"-o", exr.string(), "--png", exr.string()}, exr.string() + ": --png is the same file as -o"},
        {{"-o", exr.string(), "--report", exr.string()}, exr.string() + ": --report is the same file as -o"},
        {{"-o", exr.string(), "--report", m_scene.string()}, ": --report is the same file as the scene file"},
        {{"-o", (m_dir / "hardlink.toml").string()}, "hardlink.toml: -o is the same file as the scene file"},
        {{"-o", exr.string(), "--png", (m_dir / "symlink.png").string()}, "symlink.png: --png is the same file"},
    };
    for (const Case& c : cases) {
        ProcessResult r = render(c.args);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_TRUE(contains(r.output, c.expected)) << c.expected << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, "refusing") || contains(r.output, "each output needs its own file"));
        EXPECT_EQ(readAll(m_scene), scene) << "the scene was overwritten";
        EXPECT_FALSE(fs::exists(exr));
        EXPECT_LT(r.peakResidentBytes, kBadInputMemoryLimit);
    }
    EXPECT_TRUE(fs::is_symlink(m_dir / "symlink.png"));
}

TEST_F(OutputSafety, RenderRefusesToOverwriteItsReference)
{
    const fs::path reference = m_dir / "ref.exr";
    ASSERT_EQ(render({"-o", reference.string()}).exitCode, 0);
    const std::string before = readAll(reference);
    ProcessResult r =
        render({"-o", reference.string(), "--report", (m_dir / "r.csv").string(), "--reference", reference.string()});
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, reference.string() + ": -o is the same file as --reference")) << r.output;
    EXPECT_EQ(readAll(reference), before);
}

TEST_F(OutputSafety, MergeRefusesAnOutputThatIsAShard)
{
    // Refused before any shard is read: these need not even be EXRs.
    std::vector<fs::path> shards;
    for (int i = 0; i < 4; ++i) {
        shards.push_back(m_dir / ("s" + std::to_string(i) + ".exr"));
        writeText(shards.back(), "shard " + std::to_string(i));
    }
    ProcessResult r = runVkrt({"merge", shards[0].string(), shards[1].string(), shards[2].string(), shards[3].string(),
                               "-o", shards[1].string()});
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, shards[1].string() + ": -o is the same file as shard")) << r.output;
    EXPECT_EQ(readAll(shards[1]), "shard 1");
}

TEST_F(OutputSafety, RegressAndViewRefuseToOverwriteTheirInputs)
{
    const fs::path suite = m_dir / "suite.toml";
    writeText(suite, "# not even read\n");
    ProcessResult junit = runVkrt({"regress", "--suite", suite.string(), "--junit", suite.string()});
    EXPECT_EQ(junit.exitCode, 2) << junit.output;
    EXPECT_TRUE(contains(junit.output, suite.string() + ": --junit is the same file as the suite manifest"))
        << junit.output;
    ProcessResult report = runVkrt({"regress", "--suite", suite.string(), "--report-dir", m_dir.string(), "--junit",
                                    (m_dir / "report.md").string()});
    EXPECT_EQ(report.exitCode, 2) << report.output;
    EXPECT_TRUE(contains(report.output, "report.md: --report-dir's report.md is the same file as --junit"))
        << report.output;
    EXPECT_EQ(readAll(suite), "# not even read\n");

    ProcessResult view = runVkrt({"view", m_scene.string(), "--frames", "1", "--screenshot", m_scene.string()});
    EXPECT_EQ(view.exitCode, 2) << view.output;
    EXPECT_TRUE(contains(view.output, m_scene.string() + ": --screenshot is the same file as the scene file"))
        << view.output;
    EXPECT_EQ(readAll(m_scene), kSphereScene);
}

/// A one-triangle glTF whose buffer is the file `bufferName` beside it (any
/// name: a glTF's URIs need no extension); returns the glTF's path.
fs::path gltfWithBufferFile(const fs::path& dir, const std::string& bufferName)
{
    std::string buffer;
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) buffer.append(reinterpret_cast<char*>(&v), 4);
    writeText(dir / bufferName, buffer);
    writeText(dir / "model.gltf", R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"uri": ")" + bufferName +
                                      R"(", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]})");
    return dir / "model.gltf";
}

// Every file a scene read is an input: a glTF's buffer named like an output
// was overwritten (exit 0), and the scene no longer loaded.
TEST_F(OutputSafety, NoOutputReplacesAFileTheScenesMeshesRead)
{
    const fs::path gltf = gltfWithBufferFile(m_dir, "x.exr");
    const std::string buffer = readAll(m_dir / "x.exr");
    fs::create_symlink(m_dir / "x.exr", m_dir / "link.exr");
    fs::create_symlink(gltf, m_dir / "gltf-link.png");
    writeText(m_dir / "imports.toml", "[import]\ngltf = \"model.gltf\"\n");
    writeText(m_dir / "mesh.toml", std::string(kSphereScene) +
                                       "[[objects]]\nshape = \"mesh\"\nfile = \"model.gltf\"\nmaterial = \"white\"\n");
    const fs::path out = m_dir / "out.exr";
    struct Case {
        fs::path scene;
        std::vector<std::string> args;
        std::string expected;
    } cases[] = {
        {gltf, {"-o", (m_dir / "x.exr").string()}, "x.exr: -o is the same file as a glTF file the scene imports"},
        {gltf, {"-o", (m_dir / "link.exr").string()}, "link.exr: -o is the same file as"},
        {gltf, {"-o", out.string(), "--json", (m_dir / "x.exr").string()}, "x.exr: --json is the same file as"},
        {gltf, {"-o", out.string(), "--report", (m_dir / "x.exr").string()}, "x.exr: --report is the same file as"},
        {m_dir / "imports.toml", {"-o", (m_dir / "link.exr").string()}, "link.exr: -o is the same file as"},
        {m_dir / "imports.toml",
         {"-o", out.string(), "--png", (m_dir / "gltf-link.png").string()},
         "gltf-link.png: --png is the same file as a glTF file the scene imports"},
        {m_dir / "mesh.toml", {"-o", (m_dir / "x.exr").string()}, "x.exr: -o is the same file as a file a mesh"},
    };
    for (const Case& c : cases) {
        std::vector<std::string> args = {"render", c.scene.string(), "--spp", "1"};
        args.insert(args.end(), c.args.begin(), c.args.end());
        for (const std::string& a : deviceArgs()) args.push_back(a);
        const ProcessResult r = runVkrt(args);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_TRUE(contains(r.output, c.expected)) << c.expected << "\n" << r.output;
        EXPECT_EQ(readAll(m_dir / "x.exr"), buffer) << "the glTF's buffer was overwritten";
        EXPECT_FALSE(fs::exists(out));
    }
    EXPECT_TRUE(fs::is_symlink(m_dir / "link.exr"));
    const ProcessResult info = runVkrt({"info", gltf.string(), "--json", (m_dir / "link.exr").string()});
    EXPECT_EQ(info.exitCode, 2) << info.output;
    // The viewer's --screenshot and a script's save (its EXR and the PNG beside it): refused before any window opens.
    fs::create_symlink(m_dir / "x.exr", m_dir / "link.png");
    const ProcessResult view = runVkrt({"view", gltf.string(), "--screenshot", (m_dir / "link.png").string()});
    EXPECT_EQ(view.exitCode, 2) << view.output;
    EXPECT_TRUE(contains(view.output, "link.png: a screenshot is the same file as a glTF file the scene imports"))
        << view.output;
    writeText(m_dir / "session.txt", "frames 1\nsave " + (m_dir / "link.exr").string() + "\n");
    const ProcessResult script = runVkrt({"view", gltf.string(), "--script", (m_dir / "session.txt").string()});
    EXPECT_EQ(script.exitCode, 2) << script.output;
    EXPECT_TRUE(contains(script.output, "link.exr: a saved EXR is the same file as")) << script.output;
    EXPECT_EQ(readAll(m_dir / "x.exr"), buffer);
}

// ---------------------------------------------------------------- 1: what is at the output path

TEST_F(OutputSafety, DevicesFifosAndDirectoriesAreRefusedNotReplaced)
{
    const fs::path fifo = m_dir / "pipe.exr";
    ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
    fs::create_directory(m_dir / "folder.exr");
    struct Case {
        std::vector<std::string> args;
        std::string expected;
    } cases[] = {
        {{"-o", fifo.string()}, fifo.string() + ": is a FIFO (named pipe); vkrt writes only regular files"},
        {{"-o", "/dev/full"}, "/dev/full: is a character device"},
        {{"-o", (m_dir / "a.exr").string(), "--png", "/dev/full"}, "/dev/full: is a character device"},
        {{"-o", (m_dir / "folder.exr").string()}, "folder.exr: is a directory"},
        {{"-o", (m_dir / "no-such-dir" / "a.exr").string()}, "no-such-dir' does not exist"},
    };
    for (const Case& c : cases) {
        ProcessResult r = render(c.args);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_TRUE(contains(r.output, c.expected)) << c.expected << "\n" << r.output;
    }
    struct stat info {};
    ASSERT_EQ(lstat(fifo.c_str(), &info), 0);
    EXPECT_TRUE(S_ISFIFO(info.st_mode)) << "the FIFO was replaced";
    ASSERT_EQ(stat("/dev/full", &info), 0);
    EXPECT_TRUE(S_ISCHR(info.st_mode)) << "/dev/full was replaced";
    EXPECT_TRUE(temporariesIn(m_dir).empty());
}

TEST_F(OutputSafety, AMknodDeviceAsPngIsRefusedAndKept)
{
    if (geteuid() != 0) {
        GTEST_SKIP() << "mknod of a character device needs root";
    }
    const fs::path device = m_dir / "zero.png";
    ASSERT_EQ(mknod(device.c_str(), S_IFCHR | 0666, makedev(1, 5)), 0) << std::strerror(errno);
    ProcessResult r = render({"-o", (m_dir / "a.exr").string(), "--png", device.string()});
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, device.string() + ": is a character device")) << r.output;
    struct stat info {};
    ASSERT_EQ(lstat(device.c_str(), &info), 0);
    EXPECT_TRUE(S_ISCHR(info.st_mode));
    EXPECT_EQ(info.st_rdev, makedev(1, 5));
    EXPECT_FALSE(fs::exists(m_dir / "a.exr")) << "refused before rendering";
}

TEST_F(OutputSafety, DevNullDiscardsTheOutput)
{
    ProcessResult r = render({"-o", "/dev/null", "--png", "/dev/null"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    struct stat info {};
    ASSERT_EQ(stat("/dev/null", &info), 0);
    EXPECT_TRUE(S_ISCHR(info.st_mode));
}

TEST_F(OutputSafety, ASymlinkGetsItsTargetWrittenAndStaysALink)
{
    fs::create_directory(m_dir / "real");
    writeText(m_dir / "real" / "image.exr", "old");
    fs::create_symlink(fs::path("real") / "image.exr", m_dir / "link.exr");
    fs::create_symlink(fs::path("real") / "new.png", m_dir / "dangling.png"); // made by the write
    ProcessResult r = render({"-o", (m_dir / "link.exr").string(), "--png", (m_dir / "dangling.png").string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(fs::is_symlink(m_dir / "link.exr"));
    EXPECT_TRUE(fs::is_symlink(m_dir / "dangling.png"));
    EXPECT_EQ(readExr(m_dir / "real" / "image.exr").image.width, 32u);
    EXPECT_EQ(readAll(m_dir / "real" / "new.png").substr(1, 3), "PNG");
    EXPECT_TRUE(temporariesIn(m_dir).empty());
    EXPECT_TRUE(temporariesIn(m_dir / "real").empty());
}

TEST_F(OutputSafety, AReplacedFileKeepsItsModeAndOwner)
{
    const fs::path exr = m_dir / "private.exr", png = m_dir / "private.png";
    writeText(exr, "old");
    writeText(png, "old");
    ASSERT_EQ(chmod(exr.c_str(), 0600), 0);
    ASSERT_EQ(chmod(png.c_str(), 0640), 0);
    const bool root = geteuid() == 0;
    if (root) {
        ASSERT_EQ(chown(exr.c_str(), 1234, 5678), 0);
    }
    ASSERT_EQ(render({"-o", exr.string(), "--png", png.string()}).exitCode, 0);
    struct stat info {};
    ASSERT_EQ(stat(exr.c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 07777, 0600u);
    if (root) {
        EXPECT_EQ(std::make_pair(info.st_uid, info.st_gid), std::make_pair(uid_t(1234), gid_t(5678)));
    }
    ASSERT_EQ(stat(png.c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 07777, 0640u);
    EXPECT_NE(readAll(exr), "old");
}

TEST_F(OutputSafety, ANewFileGetsTheUmasksMode)
{
    const mode_t before = umask(027);
    ProcessResult r = render({"-o", (m_dir / "new.exr").string()});
    umask(before);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    struct stat info {};
    ASSERT_EQ(stat((m_dir / "new.exr").c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 07777, 0640u);
}

// ---------------------------------------------------------------- 3: a full disk

/// A tmpfs of a few KiB, nearly full (root only): where a write runs out of space.
class FullDisk {
public:
    explicit FullDisk(const fs::path& mountPoint) : m_mountPoint(mountPoint)
    {
        fs::create_directories(mountPoint);
        m_mounted = mount("tmpfs", mountPoint.c_str(), "tmpfs", 0, "size=64k") == 0;
    }
    ~FullDisk()
    {
        if (m_mounted) umount(m_mountPoint.c_str());
    }
    bool mounted() const { return m_mounted; }

private:
    fs::path m_mountPoint;
    bool m_mounted = false;
};

/// Writes to `file` until the file system has no space left.
void fillUp(const fs::path& file)
{
    const int fd = open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const std::string block(4096, 'x');
    while (write(fd, block.data(), block.size()) > 0) {
    }
    close(fd);
}

/// Fixture part: a full tmpfs at m_dir/full holding old.png, old.exr and old.csv (root only).
class FullDiskOutputs : public OutputSafety {
protected:
    void SetUp() override
    {
        OutputSafety::SetUp();
        if (geteuid() != 0) GTEST_SKIP() << "mounting a tiny tmpfs needs root";
        m_full = m_dir / "full";
        m_disk = std::make_unique<FullDisk>(m_full);
        if (!m_disk->mounted()) GTEST_SKIP() << "cannot mount a tmpfs here: " << std::strerror(errno);
        for (const char* name : {"old.png", "old.exr", "old.csv"}) writeText(m_full / name, std::string("was ") + name);
        fillUp(m_full / "filler");
    }
    void TearDown() override { m_disk.reset(); }

    bool kept(const char* name) const { return readAll(m_full / name) == std::string("was ") + name; }

    fs::path m_full;
    std::unique_ptr<FullDisk> m_disk;
};

TEST_F(FullDiskOutputs, APngThatDoesNotFitFailsAndKeepsTheOldFile)
{
    ProcessResult png = render({"-o", (m_dir / "a.exr").string(), "--png", (m_full / "old.png").string()});
    EXPECT_EQ(png.exitCode, 2) << png.output;
    EXPECT_TRUE(contains(png.output, (m_full / "old.png").string() + ": cannot write: No space left on device"))
        << png.output;
    EXPECT_TRUE(kept("old.png")) << "the old file was damaged";
    EXPECT_TRUE(temporariesIn(m_full).empty());
}

TEST_F(FullDiskOutputs, CheckedBytesThatDoNotFitFailAndKeepTheOldFile)
{
    EXPECT_THROW(writeBytesAtomically(m_full / "old.csv", std::string(1 << 20, 'x')), InputError);
    EXPECT_THROW(writeBytesAtomically(m_full / "old.csv", "tiny"), InputError) << "not even one page is free";
    EXPECT_TRUE(kept("old.csv")) << "the old file was damaged";
    EXPECT_TRUE(temporariesIn(m_full).empty());
}

// OpenEXR's own std::ofstream reports no error for its last buffered bytes
// (flushed in its destructor): before writeExr encoded to memory and wrote
// through writeBytesAtomically, a small EXR on a full disk was renamed over
// the old file empty, with exit 0.
TEST_F(FullDiskOutputs, AnExrThatDoesNotFitFailsAndKeepsTheOldFile)
{
    ProcessResult exr = render({"-o", (m_full / "old.exr").string()});
    EXPECT_EQ(exr.exitCode, 2) << exr.output;
    EXPECT_TRUE(contains(exr.output, (m_full / "old.exr").string() + ": cannot write")) << exr.output;
    EXPECT_TRUE(kept("old.exr")) << "the old file was damaged";
    EXPECT_TRUE(temporariesIn(m_full).empty());
}

// The convergence CSV is small enough to sit in a std::ofstream's buffer
// until close, whose error was not checked: the old report became empty.
TEST_F(FullDiskOutputs, AConvergenceReportThatDoesNotFitFailsAndKeepsTheOldFile)
{
    const fs::path image = m_dir / "a.exr";
    ProcessResult report = render({"-o", image.string(), "--report", (m_full / "old.csv").string()});
    EXPECT_EQ(report.exitCode, 2) << report.output;
    EXPECT_TRUE(contains(report.output, (m_full / "old.csv").string() + ": cannot write: No space left on device"))
        << report.output;
    EXPECT_TRUE(kept("old.csv")) << "the old report was damaged";
    EXPECT_TRUE(temporariesIn(m_full).empty());
}

// ---------------------------------------------------------------- 4 and 12: signals

/// Runs `body` in a child process and returns its wait status.
template <typename Body>
int statusOfChild(Body body)
{
    const pid_t child = fork();
    if (child == 0) {
        body();
        _exit(0);
    }
    int status = 0;
    waitpid(child, &status, 0);
    return status;
}

TEST_F(OutputSafety, TerminatingSignalsRemoveRegisteredTemporaries)
{
    for (int signal : {SIGTERM, SIGHUP, SIGINT}) {
        struct sigaction inherited {};
        sigaction(signal, nullptr, &inherited);
        if (inherited.sa_handler == SIG_IGN) continue; // ignored by our parent (nohup): vkrt keeps it so
        const fs::path temporary = m_dir / ".out.tmp-test.exr";
        writeText(temporary, "partial");
        const int status = statusOfChild([&] {
            installSignalHandlers();
            TemporaryFileGuard guard(temporary);
            raise(signal);
            _exit(99); // not reached
        });
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal) << "signal " << signal << " status " << status;
        EXPECT_FALSE(fs::exists(temporary)) << "signal " << signal;
    }
    const fs::path kept = m_dir / "kept.exr";
    writeText(kept, "done");
    statusOfChild([&] {
        {
            TemporaryFileGuard guard(kept);
        } // released: the file is the finished output now
        raise(SIGTERM);
    });
    EXPECT_TRUE(fs::exists(kept)) << "a released guard must not remove the file";
}

TEST_F(OutputSafety, TheSecondCtrlCExitsAtOnceWithoutTemporaries)
{
    const fs::path temporary = m_dir / ".out.tmp-test.exr";
    writeText(temporary, "partial");
    const int status = statusOfChild([&] {
        StopOnInterrupt stop;
        TemporaryFileGuard guard(temporary);
        raise(SIGINT);
        if (!StopOnInterrupt::stopRequested().load() || !fs::exists(temporary)) _exit(98);
        raise(SIGINT);
        _exit(99); // not reached
    });
    ASSERT_TRUE(WIFEXITED(status)) << status;
    EXPECT_EQ(WEXITSTATUS(status), 130);
    EXPECT_FALSE(fs::exists(temporary));
}

/// Waits (up to 2 s) until /proc says the process is stopped ('T').
void waitUntilStopped(pid_t pid)
{
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (std::chrono::steady_clock::now() < end) {
        std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
        std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
        const size_t close = text.rfind(')'); // the state follows the command name in parentheses
        if (close == std::string::npos || close + 2 >= text.size() || text[close + 2] == 'T') return;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
}

TEST_F(OutputSafety, SigtermWhileWritingALargeRenderLeavesNoTemporary)
{
    // The temporary of an 8 M-pixel EXR exists only while its ~100 MB are written
    // (tens of milliseconds on tmpfs), so it is not caught by polling on a busy
    // machine: inotify reports its creation, vkrt runs at the lowest priority so
    // that this process acts first, and SIGSTOP holds it (at most the write in
    // flight completes, never the rename) while SIGTERM is sent. If the rename
    // still won the race, the attempt is repeated.
    std::vector<std::string> args = {"render", m_scene.string(), "--spp", "1",  "--width",
                                     "4096",   "--height",       "2048",  "-o", (m_dir / "big.exr").string()};
    for (const std::string& a : deviceArgs()) args.push_back(a);
    bool caught = false;
    for (int attempt = 0; attempt < 5 && !caught; ++attempt) {
        fs::remove(m_dir / "big.exr");
        const int watch = inotify_init1(IN_CLOEXEC | IN_NONBLOCK);
        ASSERT_GE(watch, 0);
        ASSERT_GE(inotify_add_watch(watch, m_dir.c_str(), IN_CREATE), 0);
        RunningVkrt run = startVkrt(args, m_dir.parent_path() / (m_dir.filename().string() + ".log"));
        setpriority(PRIO_PROCESS, id_t(run.pid), 19); // before lavapipe's threads, which inherit it
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
        while (!caught && run.running() && std::chrono::steady_clock::now() < end) {
            pollfd ready{watch, POLLIN, 0};
            if (poll(&ready, 1, 100) <= 0) continue;
            alignas(inotify_event) char events[4096];
            const ssize_t n = read(watch, events, sizeof events);
            bool created = false;
            for (ssize_t at = 0; at < n;) {
                const auto* event = reinterpret_cast<const inotify_event*>(events + at);
                created = created || std::string(event->name).rfind(".big.tmp-", 0) == 0;
                at += ssize_t(sizeof(inotify_event) + event->len);
            }
            if (!created) continue;
            kill(run.pid, SIGSTOP);
            // SIGSTOP is asynchronous: look for the temporary only once the
            // process is stopped, or the rename can still follow the look
            // (seen once in the Debian 13 check).
            waitUntilStopped(run.pid);
            caught = !temporariesIn(m_dir).empty(); // false: the rename came first
            if (!caught) kill(run.pid, SIGCONT);
        }
        close(watch);
        if (!caught) {
            run.waitFor(std::chrono::seconds(60));
            continue;
        }
        kill(run.pid, SIGTERM);
        kill(run.pid, SIGCONT);
        std::optional<int> status = run.waitFor(std::chrono::seconds(30));
        ASSERT_TRUE(status);
        EXPECT_TRUE(WIFSIGNALED(*status) && WTERMSIG(*status) == SIGTERM) << *status << run.output();
        EXPECT_TRUE(temporariesIn(m_dir).empty());
        EXPECT_FALSE(fs::exists(m_dir / "big.exr"));
    }
    EXPECT_TRUE(caught) << "the temporary was never caught in 5 renders";
}

/// A Vulkan driver (ICD) whose entry point runs `body`, built with cc; empty if cc is missing.
fs::path fakeDriver(const fs::path& dir, const std::string& body)
{
    if (runShell("command -v cc").exitCode != 0) return {};
    writeText(dir / "fake_icd.c", "#include <signal.h>\n#include <unistd.h>\n"
                                  "__attribute__((visibility(\"default\"))) void* vk_icdGetInstanceProcAddr("
                                  "void* instance, const char* name) { (void)instance; (void)name; " +
                                      body + " return 0; }\n");
    const fs::path library = dir / "libfake_icd.so";
    ProcessResult cc = runShell("cc -shared -fPIC -o " + shellQuote(library.string()) + " " +
                                shellQuote((dir / "fake_icd.c").string()));
    if (cc.exitCode != 0) return {};
    const fs::path manifest = dir / "fake_icd.json";
    writeText(manifest, R"({"file_format_version": "1.0.0", "ICD": {"library_path": ")" + library.string() +
                            R"(", "api_version": "1.3.0"}})");
    return manifest;
}

std::vector<std::pair<std::string, std::string>> onlyDriver(const fs::path& manifest)
{
    return {{"VK_ICD_FILENAMES", manifest.string()}, {"VK_DRIVER_FILES", manifest.string()}};
}

TEST_F(OutputSafety, ACrashingDriverIsReportedAsSuch)
{
    const fs::path manifest = fakeDriver(m_dir, "*(volatile int*)0 = 1;");
    if (manifest.empty()) {
        GTEST_SKIP() << "no C compiler (cc) to build the fake driver";
    }
    RunningVkrt run = startVkrt({"render", m_scene.string(), "-o", (m_dir / "a.exr").string()}, m_dir / "log.txt",
                                onlyDriver(manifest));
    std::optional<int> status = run.waitFor(std::chrono::seconds(60));
    ASSERT_TRUE(status) << "hung: " << run.output();
    ASSERT_TRUE(WIFEXITED(*status)) << "died of signal " << WTERMSIG(*status) << ": " << run.output();
    EXPECT_EQ(WEXITSTATUS(*status), 5) << run.output();
    EXPECT_TRUE(contains(run.output(), "vkrt: the Vulkan driver crashed (SIGSEGV) while creating the Vulkan instance"))
        << run.output();
    EXPECT_FALSE(fs::exists(m_dir / "a.exr"));
}

TEST_F(OutputSafety, TwoCtrlCsEndARenderWhoseDriverHangs)
{
    const fs::path manifest = fakeDriver(m_dir, "for (;;) pause();");
    if (manifest.empty()) {
        GTEST_SKIP() << "no C compiler (cc) to build the fake driver";
    }
    RunningVkrt run = startVkrt({"render", m_scene.string(), "-o", (m_dir / "a.exr").string()}, m_dir / "log.txt",
                                onlyDriver(manifest));
    std::this_thread::sleep_for(std::chrono::seconds(2)); // into vkCreateInstance
    ASSERT_TRUE(run.running()) << run.output();
    kill(run.pid, SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    EXPECT_TRUE(run.running()) << "the first Ctrl-C only asks to stop";
    EXPECT_TRUE(contains(run.output(), "Ctrl-C again")) << run.output();
    kill(run.pid, SIGINT);
    std::optional<int> status = run.waitFor(std::chrono::seconds(10));
    ASSERT_TRUE(status) << "a second Ctrl-C must end it at once";
    ASSERT_TRUE(WIFEXITED(*status)) << *status;
    EXPECT_EQ(WEXITSTATUS(*status), 130);
}

} // namespace
} // namespace vkrt::test
