// The state file (docs/operations.md, Retentive memory), the start modes of a Plc over it (R4057
// power-up counter, docs/profile-fbs.md, Scan cycle and special registers), its default location,
// and the config keys of persistence and access control.

#include "support/profiles.hpp"
#include "plcemu/image/state_file.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/fiemap.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <system_error>
#include <thread>

#include "daemon/persistence.hpp"
#include "daemon/reload.hpp"
#include "plcemu/config/config.hpp"
#include "plcemu/daemon/plc.hpp"
#include "profiles/fbs/special_registers.hpp"
#include "plcemu/image/image.hpp"

namespace plcemu {
namespace {

namespace fs = std::filesystem;
using image::Area;
using image::Image;
using image::StateFile;
using image::StateOrigin;

// 2026-03-04 05:06:07 local time, for the moved-aside name.
std::time_t fixed_now() {
    std::tm tm{};
    tm.tm_year = 126;
    tm.tm_mon = 2;
    tm.tm_mday = 4;
    tm.tm_hour = 5;
    tm.tm_min = 6;
    tm.tm_sec = 7;
    tm.tm_isdst = -1;
    return std::mktime(&tm);
}

class StateFileTest : public ::testing::Test {
protected:
    void SetUp() override {
        std::string tmpl = (fs::temp_directory_path() / "plcemu-state-XXXXXX").string();
        ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
        dir_ = tmpl;
        path_ = (dir_ / "plc.state").string();
    }
    void TearDown() override { fs::remove_all(dir_); }

    static image::Layout layout() { return testing::fbs_layout(); }
    // Size of a state file for layout(): the header page and the image in whole pages.
    static std::size_t file_size() {
        return image::kDataOffset + (Image::storage_size(layout()) + 4095) / 4096 * 4096;
    }

    // Bytes of the file, for corrupting it.
    std::vector<char> read_file() const {
        std::ifstream in(path_, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), {}};
    }
    void write_file(const std::vector<char>& bytes) const {
        std::ofstream out(path_, std::ios::binary | std::ios::trunc);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
    image::StateFileHeader header() const {
        image::StateFileHeader h{};
        const auto bytes = read_file();
        std::memcpy(&h, bytes.data(), sizeof h);
        return h;
    }
    // Rewrites the header with a correct header checksum (a well-formed file that differs).
    void write_header(image::StateFileHeader h) const {
        auto bytes = read_file();
        std::memcpy(bytes.data(), &h, sizeof h);
        std::uint64_t sum = image::fnv1a64(std::as_bytes(
            std::span(bytes.data(), offsetof(image::StateFileHeader, header_checksum))));
        sum = image::fnv1a64(
            std::as_bytes(std::span(bytes.data() + sizeof h, h.retentive_count * 12)), sum);
        h.header_checksum = sum;
        std::memcpy(bytes.data(), &h, sizeof h);
        write_file(bytes);
    }
    std::vector<fs::path> bad_files() const {
        std::vector<fs::path> v;
        for (const auto& e : fs::directory_iterator(dir_)) {
            if (e.path().filename().string().find(".bad-") != std::string::npos)
                v.push_back(e.path());
        }
        std::sort(v.begin(), v.end());
        return v;
    }

    fs::path dir_;
    std::string path_;
};

TEST_F(StateFileTest, NewFileIsCreatedZeroedWithItsHeader) {
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    EXPECT_FALSE(f.retained());
    EXPECT_EQ(f.storage().size(), Image::storage_size(layout()));
    for (std::byte b : f.storage()) ASSERT_EQ(b, std::byte{0});
    // Page-aligned, so the image's own alignment holds.
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(f.storage().data()) % 4096, 0u);
    const auto h = header();
    EXPECT_EQ(std::string(h.magic, 8), "PLCEMUST");
    EXPECT_EQ(h.version, image::kStateFileVersion);
    EXPECT_EQ(h.state, image::kStateOpen);
    EXPECT_EQ(h.area_size[static_cast<int>(Area::R)], 8072u);
    EXPECT_EQ(h.retentive_count, layout().retentive.size());
    EXPECT_FALSE(fs::exists(path_ + ".new"));
}

// docs/operations.md, Retentive memory: retentive values are kept across a (clean) restart.
TEST_F(StateFileTest, ValuesSurviveCleanCloseAndReopen) {
    {
        StateFile f(path_, layout(), fixed_now());
        Image img(layout(), f.storage());
        img.set_word(Area::D, 100, 4242);
        img.set_bit(Area::M, 900, true);
    }
    EXPECT_EQ(header().state, image::kStateClosed);
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Clean);
    Image img(layout(), f.storage());
    EXPECT_EQ(img.word(Area::D, 100), 4242);
    EXPECT_TRUE(img.bit(Area::M, 900));
    EXPECT_TRUE(bad_files().empty());
}

// Every value written into the mapping is the kernel's the moment it is written: a process that
// dies without closing or syncing (as under SIGKILL) loses nothing.
TEST_F(StateFileTest, WritesSurviveAProcessThatDiesWithoutClosing) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        auto* f = new StateFile(path_, layout(), fixed_now());
        Image img(layout(), f->storage());
        for (std::uint32_t i = 0; i < 4000; ++i)
            img.set_word(Area::D, i, static_cast<std::uint16_t>(i * 7));
        ::_exit(0);  // no close, no msync, no destructors
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(header().state, image::kStateOpen);
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Recovered);
    ASSERT_FALSE(f.notes().empty());
    EXPECT_TRUE(f.notes().front().warning);
    Image img(layout(), f.storage());
    for (std::uint32_t i = 0; i < 4000; ++i) {
        ASSERT_EQ(img.word(Area::D, i), static_cast<std::uint16_t>(i * 7)) << "D" << i;
    }
}

// docs/operations.md, Retentive memory: the reason is logged either way; a start that cannot make
// the fresh file stops with an error that says where the damaged one went.
TEST_F(StateFileTest, AFreshFileThatCannotBeMadeSaysWhereTheDamagedOneWent) {
    write_file(std::vector<char>(10000, 'x'));
    fs::create_directory(path_ + ".new");  // the temporary a fresh file is made through
    try {
        StateFile f(path_, layout(), fixed_now());
        FAIL() << "a fresh file was made";
    } catch (const std::exception& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("the damaged file was moved to " + path_ + ".bad-20260304-050607"),
                  std::string::npos)
            << what;
        EXPECT_NE(what.find("bad magic"), std::string::npos) << what;
    }
    EXPECT_EQ(bad_files().size(), 1u);
}

TEST_F(StateFileTest, GarbageIsMovedAsideWithATimestampAndAFreshFileCreated) {
    write_file(std::vector<char>(10000, 'x'));
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    EXPECT_EQ(f.moved_aside(), path_ + ".bad-20260304-050607");
    const auto bad = bad_files();
    ASSERT_EQ(bad.size(), 1u);
    EXPECT_EQ(fs::file_size(bad[0]), 10000u);  // kept as it was, for a look
    bool logged = false;
    for (const auto& n : f.notes())
        logged = logged || (n.warning && n.text.find("bad magic") != std::string::npos);
    EXPECT_TRUE(logged);
    for (std::byte b : f.storage()) ASSERT_EQ(b, std::byte{0});
}

TEST_F(StateFileTest, TruncatedFileIsMovedAside) {
    { StateFile f(path_, layout(), fixed_now()); }
    auto bytes = read_file();
    bytes.resize(6000);
    write_file(bytes);
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    EXPECT_NE(f.notes().front().text.find("truncated"), std::string::npos);
}

// docs/operations.md, "Retentive memory": the file is created at exactly the header and the
// image, so bytes after them mean something else wrote into it; it is handled as corrupted.
TEST_F(StateFileTest, TrailingJunkIsMovedAside) {
    {
        StateFile f(path_, layout(), fixed_now());
        Image(layout(), f.storage()).set_word(Area::D, 5, 55);
    }
    auto bytes = read_file();
    bytes.resize(bytes.size() + 100 * 1024, 'j');
    write_file(bytes);
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    const std::string& t = f.notes().front().text;
    EXPECT_TRUE(f.notes().front().warning);
    EXPECT_NE(t.find("corrupted: 102400 bytes after the image"), std::string::npos) << t;
    ASSERT_EQ(bad_files().size(), 1u);
    EXPECT_EQ(fs::file_size(bad_files()[0]), file_size() + 100 * 1024);
    EXPECT_EQ(fs::file_size(path_), file_size());
    EXPECT_EQ(Image(layout(), f.storage()).word(Area::D, 5), 0);
}

TEST_F(StateFileTest, HeaderBitFlipIsCaughtByTheHeaderChecksum) {
    { StateFile f(path_, layout(), fixed_now()); }
    auto bytes = read_file();
    bytes[128] ^= 0x01;  // inside `created`: nothing else would notice
    write_file(bytes);
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    EXPECT_NE(f.notes().front().text.find("header checksum"), std::string::npos);
}

TEST_F(StateFileTest, DataChangedAfterACleanCloseIsCaughtByTheDataChecksum) {
    {
        StateFile f(path_, layout(), fixed_now());
        Image(layout(), f.storage()).set_word(Area::D, 5, 55);
    }
    auto bytes = read_file();
    bytes[image::kDataOffset + Image::area_offset(layout(), Area::D) + 10] ^= 0x40;
    write_file(bytes);
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    EXPECT_NE(f.notes().front().text.find("data checksum"), std::string::npos);
    EXPECT_EQ(Image(layout(), f.storage()).word(Area::D, 5), 0);
}

TEST_F(StateFileTest, AnotherLayoutDoesNotMatchAndIsMovedAside) {
    { StateFile f(path_, layout(), fixed_now()); }
    image::Layout other = layout();
    other.set_size(Area::D, 8000);
    StateFile f(path_, other, fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    const std::string& t = f.notes().front().text;
    EXPECT_NE(t.find("does not match"), std::string::npos) << t;
    EXPECT_NE(t.find("D area has 4000 devices, not 8000"), std::string::npos) << t;
    EXPECT_EQ(bad_files().size(), 1u);
}

TEST_F(StateFileTest, AnotherFormatVersionDoesNotMatch) {
    { StateFile f(path_, layout(), fixed_now()); }
    auto h = header();
    h.version = 99;
    write_header(h);
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Created);
    EXPECT_NE(f.notes().front().text.find("format version 99"), std::string::npos);
}

TEST_F(StateFileTest, SecondBadFileInTheSameSecondGetsItsOwnName) {
    write_file(std::vector<char>(100, 'a'));
    { StateFile f(path_, layout(), fixed_now()); }
    write_file(std::vector<char>(200, 'b'));
    StateFile f(path_, layout(), fixed_now());
    const auto bad = bad_files();
    ASSERT_EQ(bad.size(), 2u);
    EXPECT_EQ(bad[0].filename().string(), "plc.state.bad-20260304-050607");
    EXPECT_EQ(bad[1].filename().string(), "plc.state.bad-20260304-050607-1");
    EXPECT_EQ(fs::file_size(bad[1]), 200u);
}

TEST_F(StateFileTest, ASecondUserIsRefusedAndTheFileLeftAlone) {
    StateFile f(path_, layout(), fixed_now());
    EXPECT_THROW(StateFile(path_, layout(), fixed_now()), std::system_error);
    EXPECT_TRUE(bad_files().empty());
}

// docs/operations.md, "Retentive memory": a second user of a new file is refused by name and the
// first one's values are left alone.
TEST_F(StateFileTest, ASecondUserOfANewFileIsRefusedByNameAndTheFirstKeepsItsValues) {
    StateFile f(path_, layout(), fixed_now());
    Image img(layout(), f.storage());
    img.set_word(Area::D, 3, 333);
    try {
        StateFile second(path_, layout(), fixed_now());
        ADD_FAILURE() << "a second StateFile opened " << path_;
    } catch (const std::system_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("state file " + path_), std::string::npos) << what;
        EXPECT_NE(what.find("in use by another process"), std::string::npos) << what;
    }
    EXPECT_EQ(img.word(Area::D, 3), 333);
    EXPECT_EQ(fs::file_size(path_), file_size());
    EXPECT_FALSE(fs::exists(path_ + ".new"));
}

// The lock is taken before anything is created, so a daemon starting while another is still
// creating the file cannot truncate or replace it under the other's mapping (SIGBUS).
TEST_F(StateFileTest, WhileTheLockIsHeldNothingIsCreatedOrTruncated) {
    const int fd = ::open((path_ + ".lock").c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
    const std::string tmp = path_ + ".new";
    std::ofstream(tmp) << "half-made by the lock holder";
    try {
        StateFile f(path_, layout(), fixed_now());
        ADD_FAILURE() << "opened " << path_ << " while another process held its lock";
    } catch (const std::system_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(path_), std::string::npos) << what;
        EXPECT_NE(what.find("in use by another process"), std::string::npos) << what;
    }
    ::close(fd);
    std::string left;
    std::getline(std::ifstream(tmp), left);
    EXPECT_EQ(left, "half-made by the lock holder");
    EXPECT_FALSE(fs::exists(path_));
}

// Processes started at the same instant on a new file: exactly one gets it, the others are
// refused naming the file, none dies of a signal, and the winner's values are intact.
TEST_F(StateFileTest, ProcessesCreatingOneNewFileAtOnceLetExactlyOneWin) {
    constexpr int kRounds = 10;
    constexpr int kProcesses = 4;
    for (int round = 0; round < kRounds; ++round) {
        const std::string path = (dir_ / ("race" + std::to_string(round) + ".state")).string();
        int go[2];
        ASSERT_EQ(::pipe(go), 0);
        std::vector<pid_t> pids;
        for (int k = 0; k < kProcesses; ++k) {
            const pid_t pid = ::fork();
            if (pid == 0) {
                ::close(go[1]);
                char c;
                (void)!::read(go[0], &c, 1);  // end of file when the parent closes: all go
                try {
                    StateFile f(path, layout(), fixed_now());
                    Image img(layout(), f.storage());
                    const auto mine = static_cast<std::uint16_t>(1000 + k);
                    for (std::uint32_t i = 0; i < 4000; ++i) img.set_word(Area::D, i, mine);
                    ::usleep(400'000);  // holds the file while the others try
                    for (std::uint32_t i = 0; i < 4000; ++i) {
                        if (img.word(Area::D, i) != mine) ::_exit(4);
                    }
                    f.close();
                    ::_exit(0);
                } catch (const std::system_error& e) {
                    const std::string what = e.what();
                    const bool named = what.find("state file " + path) != std::string::npos &&
                                       what.find("in use by another process") != std::string::npos;
                    ::_exit(named ? 1 : 2);
                } catch (...) {
                    ::_exit(3);
                }
            }
            if (pid > 0) pids.push_back(pid);
        }
        ::close(go[0]);
        ::close(go[1]);
        ASSERT_EQ(pids.size(), static_cast<std::size_t>(kProcesses));
        int winner = -1;
        int refused = 0;
        for (int k = 0; k < kProcesses; ++k) {
            int status = 0;
            ASSERT_EQ(::waitpid(pids[k], &status, 0), pids[k]);
            ASSERT_TRUE(WIFEXITED(status))
                << "round " << round << ": process " << k << " died of signal " << WTERMSIG(status);
            const int code = WEXITSTATUS(status);
            ASSERT_TRUE(code == 0 || code == 1) << "round " << round << ": exit code " << code;
            if (code == 0) {
                EXPECT_EQ(winner, -1) << "round " << round << ": two processes got the file";
                winner = k;
            } else {
                ++refused;
            }
        }
        ASSERT_NE(winner, -1) << "round " << round << ": nobody got the file";
        EXPECT_EQ(refused, kProcesses - 1);
        StateFile f(path, layout(), fixed_now());
        EXPECT_EQ(f.origin(), StateOrigin::Clean);
        Image img(layout(), f.storage());
        EXPECT_EQ(img.word(Area::D, 0), 1000 + winner);
        EXPECT_EQ(img.word(Area::D, 3999), 1000 + winner);
        EXPECT_FALSE(fs::exists(path + ".new"));
    }
}

// The blocks of a new file are allocated up front, so a write into the mapping can never fault
// (SIGBUS) later because the disk has filled up meanwhile.
// docs/operations.md, "Retentive memory": no file of the set is reached through a symlink as its
// last component. A `.new` planted as a link is removed as a link; its target is never written.
TEST_F(StateFileTest, ATemporaryPlantedAsALinkIsRemovedAndItsTargetNeverWritten) {
    const fs::path victim = dir_ / "victim";
    { std::ofstream(victim) << "precious"; }
    fs::create_symlink(victim, path_ + ".new");
    {
        StateFile f(path_, layout(), fixed_now());
        EXPECT_EQ(f.origin(), StateOrigin::Created);
        Image(layout(), f.storage()).set_word(Area::D, 1, 11);
        bool logged = false;
        for (const auto& n : f.notes())
            logged = logged || (n.warning && n.text.find("symbolic link") != std::string::npos);
        EXPECT_TRUE(logged);
    }
    EXPECT_EQ(fs::file_size(victim), 8u);
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(path_)));
    EXPECT_FALSE(fs::exists(fs::symlink_status(path_ + ".new")));
    EXPECT_EQ(header().state, image::kStateClosed);
}

TEST_F(StateFileTest, AStateFileThatIsALinkIsRefusedAndItsTargetLeftAlone) {
    const fs::path victim = dir_ / "victim";
    { std::ofstream(victim) << "precious"; }
    fs::create_symlink(victim, path_);
    try {
        StateFile f(path_, layout(), fixed_now());
        FAIL() << "a symlink was used as the state file";
    } catch (const std::system_error& e) {
        EXPECT_NE(std::string(e.what()).find(path_ + " is a symbolic link"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(fs::file_size(victim), 8u);
    EXPECT_TRUE(fs::is_symlink(path_));
    EXPECT_TRUE(bad_files().empty());
}

TEST_F(StateFileTest, ALockThatIsADanglingLinkIsRefusedAndItsTargetNotCreated) {
    const fs::path target = dir_ / "created-by-nobody";
    fs::create_symlink(target, path_ + ".lock");
    try {
        StateFile f(path_, layout(), fixed_now());
        FAIL() << "a symlink was followed as the lock";
    } catch (const std::system_error& e) {
        EXPECT_NE(std::string(e.what()).find(path_ + ".lock is a symbolic link"), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(fs::symlink_status(target)));
    EXPECT_FALSE(fs::exists(fs::symlink_status(path_)));
}

TEST_F(StateFileTest, ALockThatIsNotARegularFileIsRefused) {
    ASSERT_EQ(::mkfifo((path_ + ".lock").c_str(), 0600), 0);
    EXPECT_THROW(StateFile(path_, layout(), fixed_now()), std::system_error);
    EXPECT_FALSE(fs::exists(path_));
}

// Directories on the way may be links: the file is made and reopened in the one they lead to.
TEST_F(StateFileTest, AFileReachedThroughALinkedDirectoryIsUsed) {
    fs::create_directory(dir_ / "real");
    fs::create_directory_symlink(dir_ / "real", dir_ / "linked");
    const std::string through = (dir_ / "linked" / "plc.state").string();
    {
        StateFile f(through, layout(), fixed_now());
        Image(layout(), f.storage()).set_word(Area::D, 3, 33);
    }
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir_ / "real" / "plc.state")));
    StateFile f(through, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Clean);
    EXPECT_EQ(Image(layout(), f.storage()).word(Area::D, 3), 33);
}

TEST_F(StateFileTest, ANewFileHasEveryBlockReserved) {
    StateFile f(path_, layout(), fixed_now());
    struct stat st {};
    ASSERT_EQ(::stat(path_.c_str(), &st), 0);
    EXPECT_GE(static_cast<std::uint64_t>(st.st_blocks) * 512,
              static_cast<std::uint64_t>(st.st_size));
}

// A sparse file (as written before blocks were reserved) gets its blocks when it is opened.
TEST_F(StateFileTest, ASparseFileGetsEveryBlockReservedWhenOpened) {
    { StateFile f(path_, layout(), fixed_now()); }
    const int fd = ::open(path_.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    const auto size = static_cast<off_t>(fs::file_size(path_));
    // The image is all zero, so punching it out changes no byte and no checksum.
    const int punched = ::fallocate(fd, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE,
                                    image::kDataOffset, size - image::kDataOffset);
    ::close(fd);
    struct stat st {};
    ASSERT_EQ(::stat(path_.c_str(), &st), 0);
    if (punched != 0 || static_cast<off_t>(st.st_blocks) * 512 >= size) {
        GTEST_SKIP() << "this file system cannot punch holes";
    }
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Clean);
    ASSERT_EQ(::stat(path_.c_str(), &st), 0);
    EXPECT_GE(static_cast<off_t>(st.st_blocks) * 512, size);
}

// Bytes of `path` in extents the file system reports "unwritten" (reserved, never written), or
// -1 when it cannot say (no FIEMAP).
long long unwritten_bytes(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return -1;
    std::vector<std::uint64_t> buf((sizeof(fiemap) + 64 * sizeof(fiemap_extent)) / 8 + 1, 0);
    auto* map = reinterpret_cast<fiemap*>(buf.data());
    map->fm_length = FIEMAP_MAX_OFFSET;
    map->fm_extent_count = 64;
    const int r = ::ioctl(fd, FS_IOC_FIEMAP, map);
    ::close(fd);
    if (r != 0) return -1;
    long long n = 0;
    for (std::uint32_t i = 0; i < map->fm_mapped_extents; ++i) {
        if ((map->fm_extents[i].fe_flags & FIEMAP_EXTENT_UNWRITTEN) != 0)
            n += static_cast<long long>(map->fm_extents[i].fe_length);
    }
    return n;
}

// ext4 reads a reserved, never written block as zeros, and keeps reading it so after a write of
// it failed even once later writes succeed (docs/operations.md, "a disk that refuses writes"):
// a new file has every block written, and one from an earlier version, reserved only, gets them
// written when it is opened, its values kept.
TEST_F(StateFileTest, EveryBlockOfTheFileIsWrittenNotOnlyReserved) {
    {
        StateFile f(path_, layout(), fixed_now());
        Image(layout(), f.storage()).set_word(Area::D, 3, 33);
    }
    const long long fresh = unwritten_bytes(path_);
    if (fresh < 0) GTEST_SKIP() << "this file system has no FIEMAP";
    EXPECT_EQ(fresh, 0);
    // As an earlier version left it: the image's last pages reserved and never written (D3,
    // in an earlier page, keeps its value).
    const int fd = ::open(path_.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    const auto size = static_cast<off_t>(fs::file_size(path_));
    const off_t from = size - 2 * 4096;
    const bool redone =
        ::fallocate(fd, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, from, size - from) == 0 &&
        ::fallocate(fd, 0, from, size - from) == 0;
    ::close(fd);
    if (!redone || unwritten_bytes(path_) <= 0) {
        GTEST_SKIP() << "this file system does not keep reserved blocks unwritten";
    }
    StateFile f(path_, layout(), fixed_now());
    EXPECT_EQ(unwritten_bytes(path_), 0);
    EXPECT_EQ(Image(layout(), f.storage()).word(Area::D, 3), 33);
}

// A file that cannot get its blocks (over RLIMIT_FSIZE here, as on a full disk) is refused at
// once, naming the file and the size, and nothing half-made is left behind.
TEST_F(StateFileTest, AFileThatCannotGetItsBlocksIsRefusedAndNothingIsLeftBehind) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        std::signal(SIGXFSZ, SIG_IGN);  // the EFBIG return is what is tested
        const rlimit limit{8192, 8192};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        try {
            StateFile f(path_, layout(), fixed_now());
            ::_exit(3);
        } catch (const std::system_error& e) {
            const std::string what = e.what();
            const bool told =
                what.find("state file " + path_ + ": cannot reserve " +
                          std::to_string(file_size()) + " bytes") != std::string::npos;
            ::_exit(told ? 0 : 1);
        } catch (...) {
            ::_exit(2);
        }
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0)
        << "3: opened anyway, 1: another message, 2: not system_error";
    EXPECT_FALSE(fs::exists(path_));
    EXPECT_FALSE(fs::exists(path_ + ".new"));
}

// docs/operations.md, Retentive memory: a sync writes the pages whose retentive devices (or
// header) changed, not those where only devices cleared at every start did.
TEST_F(StateFileTest, ASyncWritesOnlyThePagesWhoseRetentiveDevicesChanged) {
    StateFile f(path_, layout(), fixed_now());
    Image img(layout(), f.storage());
    img.clear();  // every page in the page cache, and changed
    const std::uint64_t pages = file_size() / 4096;
    auto written = [&, last = std::uint64_t{0}]() mutable {
        EXPECT_TRUE(f.sync());
        const std::uint64_t n = f.pages_synced() - last;
        last = f.pages_synced();
        return n;
    };
    EXPECT_EQ(written(), pages) << "the first sync writes the whole file";
    EXPECT_EQ(written(), 0u) << "nothing changed";
    // R4128 (not retentive by default) shares its page with R5000 (retentive).
    img.set_word(Area::R, 4128, 1);
    img.set_bit(Area::M, 1920, true);
    EXPECT_EQ(written(), 0u) << "only devices cleared at every start changed";
    img.set_word(Area::D, 100, 7);
    EXPECT_EQ(written(), 1u);
    img.set_word(Area::D, 100, 7);
    EXPECT_EQ(written(), 0u) << "the same value again";
    img.set_word(Area::D, 100, 8);
    img.set_word(Area::D, 101, 9);
    EXPECT_EQ(written(), 1u) << "two devices of one page";
    img.set_word(Area::R, 0, 1);
    img.set_word(Area::D, 3000, 1);
    img.set_bit(Area::M, 900, true);
    EXPECT_EQ(written(), 3u) << "three pages";
    img.set_word(Area::R, 5000, 3);
    EXPECT_EQ(written(), 1u) << "a retentive device beside R4128";
    // New ranges: every page is written once, then R4128's changes count.
    auto more = layout().retentive;
    more.push_back({Area::R, 4128, 1});
    f.set_retentive(more);
    EXPECT_EQ(written(), pages);
    img.set_word(Area::R, 4128, 2);
    EXPECT_EQ(written(), 1u);
    EXPECT_EQ(written(), 0u);
}

// A page written back and dropped from the page cache is on the disk: it is not read back in
// to be summed, and once back and changed it is written again.
TEST_F(StateFileTest, APageOutsideThePageCacheIsLeftOnTheDiskUntilItIsBack) {
    StateFile f(path_, layout(), fixed_now());
    Image img(layout(), f.storage());
    img.clear();
    ASSERT_TRUE(f.sync());
    const std::uint64_t before = f.pages_synced();
    // Drop the page of D3000 from the page cache (it is clean: just written).
    auto* page = reinterpret_cast<std::byte*>(&img.words(Area::D)[3000]);
    page -= reinterpret_cast<std::uintptr_t>(page) % 4096;
    ASSERT_EQ(::madvise(page, 4096, MADV_DONTNEED), 0);
    const int fd = ::open(path_.c_str(), O_RDONLY);
    ASSERT_GE(fd, 0);
    const auto at = static_cast<off_t>(image::kDataOffset + (page - f.storage().data()));
    ASSERT_EQ(::posix_fadvise(fd, at, 4096, POSIX_FADV_DONTNEED), 0);
    unsigned char in_cache = 1;
    ASSERT_EQ(::mincore(page, 4096, &in_cache), 0);
    if ((in_cache & 1) != 0) {
        ::close(fd);
        GTEST_SKIP() << "this file system keeps clean pages in its cache";
    }
    ASSERT_TRUE(f.sync());
    EXPECT_EQ(f.pages_synced(), before);
    ASSERT_EQ(::mincore(page, 4096, &in_cache), 0);
    EXPECT_EQ(in_cache & 1, 0) << "the sync read the page back in";
    img.set_word(Area::D, 3000, 5);
    ASSERT_TRUE(f.sync());
    EXPECT_EQ(f.pages_synced(), before + 1);
    ::close(fd);
}

TEST_F(StateFileTest, ChangedRetentiveRangesKeepOnlyDevicesRetentiveBeforeAndNow) {
    image::Layout before = layout();
    before.retentive = {{Area::D, 0, 100}};
    {
        StateFile f(path_, before, fixed_now());
        Image img(before, f.storage());
        img.set_word(Area::D, 50, 1);   // retentive then and now
        img.set_word(Area::D, 150, 2);  // retentive now only: held live data then
    }
    image::Layout now = layout();
    now.retentive = {{Area::D, 0, 200}};
    StateFile f(path_, now, fixed_now());
    EXPECT_EQ(f.origin(), StateOrigin::Clean);
    Image img(now, f.storage());
    EXPECT_EQ(img.word(Area::D, 50), 1);
    EXPECT_EQ(img.word(Area::D, 150), 0);
    EXPECT_EQ(header().retentive_count, 1u);
    EXPECT_TRUE(bad_files().empty());
}

// The same devices listed in another order or split otherwise are no change: nothing is
// cleared and nothing is said.
TEST_F(StateFileTest, RetentiveRangesReorderedOrSplitAreNoChange) {
    image::Layout before = layout();
    before.retentive = {{Area::D, 0, 11}, {Area::R, 0, 11}};
    {
        StateFile f(path_, before, fixed_now());
        Image(before, f.storage()).set_word(Area::R, 5, 7);
    }
    image::Layout now = layout();
    now.retentive = {{Area::R, 5, 6}, {Area::R, 0, 5}, {Area::D, 0, 11}};
    StateFile f(path_, now, fixed_now());
    EXPECT_EQ(Image(now, f.storage()).word(Area::R, 5), 7);
    for (const auto& n : f.notes()) {
        EXPECT_EQ(n.text.find("retentive ranges changed"), std::string::npos) << n.text;
    }
    f.close();
    now.retentive = {{Area::R, 0, 10}, {Area::D, 0, 11}};  // R10 is not retentive any more
    StateFile g(path_, now, fixed_now());
    bool said = false;
    for (const auto& n : g.notes())
        said = said || n.text.find("ranges changed") != std::string::npos;
    EXPECT_TRUE(said);
}

// ---- Plc over a state file: start modes, R4057, init policy

config::Config plc_config(const std::string& extra = "") {
    return config::parse_config("profile: fbs\n" + extra, "test.yaml");
}

std::uint16_t power_ups(daemon::Plc& plc) {
    return plc.image().word(Area::R, profiles::fbs::special::kPowerUps);
}

// docs/operations.md, Retentive memory: "devices outside the retentive ranges are cleared and R4057
// counts the start".
TEST_F(StateFileTest, EachStartCountsInR4057AndClearsNonRetentiveDevices) {
    const auto cfg = plc_config();
    for (int start = 1; start <= 3; ++start) {
        StateFile f(path_, daemon::plc_layout(cfg), fixed_now());
        daemon::Plc plc(cfg, f.storage(),
                        f.retained() ? daemon::Start::Retained : daemon::Start::Fresh);
        EXPECT_EQ(power_ups(plc), start);
        EXPECT_EQ(plc.image().word(Area::R, 3000), 0) << "R3000 is not retentive";
        EXPECT_EQ(plc.image().word(Area::D, 7), start == 1 ? 0 : 70 + start - 1);
        plc.image().set_word(Area::R, 3000, 9);
        plc.image().set_word(Area::D, 7, static_cast<std::uint16_t>(70 + start));
    }
}

TEST_F(StateFileTest, R4057StaysRetentiveWhenTheConfigNamesOtherRanges) {
    const auto cfg = plc_config("persistence: {retentive: [D0-D9]}\n");
    const auto l = daemon::plc_layout(cfg);
    ASSERT_EQ(l.retentive.size(), 2u);
    EXPECT_EQ(l.retentive[1], (image::Range{Area::R, 4057, 1}));
}

// The most ranges a config may list (256) and the R4057 the family adds: the file takes them all,
// at the start and at a reload (a file that refused the 257th stopped the daemon).
TEST_F(StateFileTest, TheMostRangesAConfigMayListFitBesideR4057) {
    std::string ranges;
    for (int i = 0; i < static_cast<int>(image::kMaxConfiguredRanges); ++i) {
        ranges += (i == 0 ? "" : ", ") + std::string("D") + std::to_string(2 * i);
    }
    const auto cfg = plc_config("persistence: {retentive: [" + ranges + "]}\n");
    const auto l = daemon::plc_layout(cfg);
    ASSERT_EQ(l.retentive.size(), image::kMaxConfiguredRanges + 1);
    {
        StateFile f(path_, layout(), fixed_now());
        f.set_retentive(l.retentive);
    }
    StateFile f(path_, l, fixed_now());
    EXPECT_EQ(header().retentive_count, image::kMaxConfiguredRanges + 1);
}

// Decision (docs/operations.md): init presets reach retentive devices only on a fresh state file,
// unless persistence.init is `always`; non-retentive devices get them at every start.
TEST_F(StateFileTest, InitPresetsDoNotOverwriteRetainedValuesByDefault) {
    const auto cfg = plc_config("init: {R10: 111, R3000: 7, WM792: 0xFFFF}\n");
    {
        StateFile f(path_, daemon::plc_layout(cfg), fixed_now());
        daemon::Plc plc(cfg, f.storage(), daemon::Start::Fresh);
        EXPECT_EQ(plc.image().word(Area::R, 10), 111);
        EXPECT_TRUE(plc.image().bit(Area::M, 800));
        plc.image().set_word(Area::R, 10, 222);  // a SCADA's retained write
        plc.image().set_word(Area::R, 3000, 9);
        plc.image().set_bit(Area::M, 800, false);  // M800 retentive, M792-M799 not
        plc.image().set_bit(Area::M, 795, false);
    }
    StateFile f(path_, daemon::plc_layout(cfg), fixed_now());
    daemon::Plc plc(cfg, f.storage(), daemon::Start::Retained);
    EXPECT_EQ(plc.image().word(Area::R, 10), 222);
    EXPECT_EQ(plc.image().word(Area::R, 3000), 7);
    EXPECT_FALSE(plc.image().bit(Area::M, 800));
    EXPECT_TRUE(plc.image().bit(Area::M, 795));
}

TEST_F(StateFileTest, InitAlwaysOverwritesRetainedValues) {
    const auto cfg = plc_config("init: {R10: 111}\npersistence: {init: always}\n");
    {
        StateFile f(path_, daemon::plc_layout(cfg), fixed_now());
        daemon::Plc plc(cfg, f.storage(), daemon::Start::Fresh);
        plc.image().set_word(Area::R, 10, 222);
    }
    StateFile f(path_, daemon::plc_layout(cfg), fixed_now());
    daemon::Plc plc(cfg, f.storage(), daemon::Start::Retained);
    EXPECT_EQ(plc.image().word(Area::R, 10), 111);
}

TEST_F(StateFileTest, ReloadKeepsTheWholeImageAndDoesNotCountAPowerUp) {
    const auto cfg = plc_config();
    StateFile f(path_, daemon::plc_layout(cfg), fixed_now());
    auto plc = std::make_unique<daemon::Plc>(cfg, f.storage(), daemon::Start::Fresh);
    plc->image().set_word(Area::R, 3000, 9);  // not retentive
    plc->image().set_word(Area::R, 4005, 0x0203);
    plc.reset();
    const auto next = plc_config("station: 5\n");
    daemon::Plc reloaded(next, f.storage(), daemon::Start::Reload);
    EXPECT_EQ(power_ups(reloaded), 1);
    EXPECT_EQ(reloaded.image().word(Area::R, 3000), 9);
    EXPECT_EQ(reloaded.image().word(Area::R, 4005), 0x0203);
    EXPECT_EQ(reloaded.engine().station(), 5);
}

// ---- every PLC's state file at a start

// 100 configs start three threads; the PLCs are built in order as their files come.
TEST_F(StateFileTest, StateFilesComeToTheStartInOrderEachOpenOrWithItsError) {
    std::vector<config::Config> cfgs(100, plc_config());
    for (std::size_t i = 0; i < cfgs.size(); ++i) {
        cfgs[i].persistence.file = (dir_ / ("plc" + std::to_string(i) + ".state")).string();
    }
    cfgs[40].persistence.enabled = false;
    cfgs[70].persistence.file = (dir_ / "missing" / "plc70.state").string();
    std::vector<const config::Config*> ptrs;
    ptrs.reserve(cfgs.size());
    for (const auto& c : cfgs) ptrs.push_back(&c);
    std::vector<std::size_t> order;
    daemon::open_state_files(ptrs, "", fixed_now(), [&](std::size_t i, daemon::OpenedState s) {
        order.push_back(i);
        if (i == 40) {
            EXPECT_EQ(s.file, nullptr);
            EXPECT_EQ(s.error, nullptr);
        } else if (i == 70) {
            EXPECT_EQ(s.file, nullptr);
            EXPECT_NE(s.error, nullptr);
        } else {
            ASSERT_NE(s.file, nullptr) << i;
            EXPECT_EQ(s.file->path(), cfgs[i].persistence.file);
            EXPECT_EQ(s.error, nullptr);
        }
    });
    std::vector<std::size_t> expected(cfgs.size());
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(order, expected);
    EXPECT_FALSE(fs::exists(dir_ / "plc40.state"));
    EXPECT_TRUE(fs::exists(dir_ / "plc99.state"));
}

// What the start throws on a PLC's file comes out once the threads ended: nothing is made after.
TEST_F(StateFileTest, AStartStoppedByOnePlcMakesNoFileAfterItReturns) {
    std::vector<config::Config> cfgs(200, plc_config());
    for (std::size_t i = 0; i < cfgs.size(); ++i) {
        cfgs[i].persistence.file = (dir_ / ("plc" + std::to_string(i) + ".state")).string();
    }
    std::vector<const config::Config*> ptrs;
    ptrs.reserve(cfgs.size());
    for (const auto& c : cfgs) ptrs.push_back(&c);
    std::size_t calls = 0;
    EXPECT_THROW(daemon::open_state_files(ptrs, "", fixed_now(),
                                          [&](std::size_t i, daemon::OpenedState) {
                                              ++calls;
                                              if (i == 3) throw std::runtime_error("PLC 3");
                                          }),
                 std::runtime_error);
    EXPECT_EQ(calls, 4u);
    const auto count = [&] {
        return std::distance(fs::directory_iterator(dir_), fs::directory_iterator{});
    };
    const auto after = count();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_EQ(count(), after);
}

// ---- where the state file lives

TEST(StateFilePath, DefaultIsBesideTheConfigNamedAfterIt) {
    auto cfg = plc_config();
    cfg.path = "/etc/plcemu/line1.yaml";
    EXPECT_EQ(config::state_file_path(cfg, ""), "/etc/plcemu/line1.state");
    cfg.path = "plc.yaml";
    EXPECT_EQ(config::state_file_path(cfg, ""), "./plc.state");
}

TEST(StateFilePath, SystemdStateDirectoryWinsForRelativeNames) {
    auto cfg = plc_config();
    cfg.path = "/etc/plcemu/plcemud.yaml";
    EXPECT_EQ(config::state_file_path(cfg, "/var/lib/plcemu"), "/var/lib/plcemu/plcemud.state");
    EXPECT_EQ(config::state_file_path(cfg, "/var/lib/a:/var/lib/b"), "/var/lib/a/plcemud.state");
    cfg.persistence.file = "other.state";
    EXPECT_EQ(config::state_file_path(cfg, "/var/lib/plcemu"), "/var/lib/plcemu/other.state");
    cfg.persistence.file = "/srv/x.state";
    EXPECT_EQ(config::state_file_path(cfg, "/var/lib/plcemu"), "/srv/x.state");
}

// ---- config keys

std::string config_error(const std::string& text) {
    try {
        config::parse_config(text, "c.yaml");
    } catch (const config::ConfigError& e) {
        return e.what();
    }
    return "";
}

TEST(PersistenceConfig, KeysAndDefaults) {
    const auto d = plc_config();
    EXPECT_TRUE(d.persistence.enabled);
    EXPECT_EQ(d.persistence.init, config::InitPolicy::Fresh);
    const auto c = plc_config("persistence: {enabled: false, init: always, sync_ms: 250}\n");
    EXPECT_FALSE(c.persistence.enabled);
    EXPECT_EQ(c.persistence.init, config::InitPolicy::Always);
    EXPECT_EQ(c.persistence.sync_ms, 250);
    EXPECT_EQ(
        config_error("profile: fbs\npersistence: {init: sometimes}\n").rfind("c.yaml:2:21:", 0),
        0u);
}

TEST(AccessConfig, BadEntriesNameTheirPosition) {
    EXPECT_EQ(config_error("profile: fbs\nmodbus:\n  tcp:\n    allow: [127.0.0.0/8, 10.0.0.0/33]\n")
                  .rfind("c.yaml:4:26: modbus.tcp.allow", 0),
              0u);
    EXPECT_EQ(
        config_error("profile: fbs\nmodbus: {tcp: {allow: [bogus]}}\n").rfind("c.yaml:2:24:", 0),
        0u);
    EXPECT_EQ(
        config_error("profile: fbs\nmodbus: {tcp: {bind: localhost}}\n").rfind("c.yaml:2:22:", 0),
        0u);
    EXPECT_NE(
        config_error("profile: fbs\nmodbus: {write_protect: [D3990-D4010]}\n").find("outside"),
        std::string::npos);
    EXPECT_NE(
        config_error("profile: fbs\npersistence: {retentive: [M2000-M2100]}\n").find("outside"),
        std::string::npos);
    EXPECT_EQ(config_error("profile: fbs\nmodbus: {tcp: {allow: ['::1/128', 10.1.2.3]}}\n"), "");
}

TEST(Reload, ChangesAreListed) {
    const auto a = plc_config("station: 1\nmodbus: {tcp: {port: 5020, allow: [127.0.0.1]}}\n");
    const auto b = plc_config("station: 7\nmodbus: {tcp: {port: 5020, max_clients: 2}}\n");
    const auto changes = daemon::config_changes(a, b);
    ASSERT_EQ(changes.size(), 3u);
    EXPECT_EQ(changes[0], "station: 1 -> 7");
    EXPECT_EQ(changes[1], "modbus.tcp.allow: [127.0.0.1] -> []");
    EXPECT_EQ(changes[2], "modbus.tcp.max_clients: 64 -> 2");
    EXPECT_TRUE(daemon::config_changes(a, a).empty());
}

// A state file named otherwise but the same file ("sub/x.state", "./sub/x.state") was logged as
// "persistence.file: sub/x.state -> ./sub/x.state".
TEST(Reload, TheSameStateFileWrittenOtherwiseIsNoChange) {
    const auto a = plc_config("persistence: {file: sub/x.state}\n");
    const auto b = plc_config("persistence: {file: ./sub//x.state}\n");
    EXPECT_TRUE(daemon::config_changes(a, b).empty());
    const auto c = plc_config("persistence: {file: sub/y.state}\n");
    EXPECT_EQ(daemon::config_changes(a, c),
              std::vector<std::string>{"persistence.file: sub/x.state -> sub/y.state"});
    // The default is test.yaml's name made into a state file's: written out, it is the same.
    EXPECT_TRUE(
        daemon::config_changes(plc_config(), plc_config("persistence: {file: test.state}\n"))
            .empty());
    // Under a state directory ($STATE_DIRECTORY, as systemd sets it) relative names are placed
    // there, as the daemon places them: its path written out is no change, while the config's
    // directory is another file.
    const auto in_dir = plc_config("persistence: {file: /srv/st/x.state}\n");
    const auto x = plc_config("persistence: {file: x.state}\n");
    EXPECT_TRUE(daemon::config_changes(x, in_dir, "/srv/st").empty());
    EXPECT_TRUE(daemon::config_changes(x, plc_config("persistence: {file: ./x.state}\n"), "/srv/st")
                    .empty());
    EXPECT_EQ(daemon::config_changes(x, in_dir, ""),
              std::vector<std::string>{"persistence.file: x.state -> /srv/st/x.state"});
}

// Retentive ranges are compared as the devices they cover, as the state file compares them.
TEST(Reload, RetentiveRangesReorderedAreNoChange) {
    const auto a = plc_config("persistence: {retentive: [D0-D9, R0-R9]}\n");
    const auto b = plc_config("persistence: {retentive: [R0-R4, R5-R9, D0-D9]}\n");
    EXPECT_TRUE(daemon::config_changes(a, b).empty());
    const auto c = plc_config("persistence: {retentive: [R0-R9, D0-D8]}\n");
    EXPECT_EQ(daemon::config_changes(a, c),
              std::vector<std::string>{"persistence.retentive: changed"});
}

// Every listener's settings are listed, FATEK's too (a FATEK-only change was "no setting
// changed"), and a line as the log names it elsewhere (9600 8E1).
TEST(Reload, EveryListenersChangesAreListed) {
    const auto a = plc_config(
        "modbus: {tcp: {port: 5020}, rtu: {device: /dev/ttyS1}}\n"
        "fatek: {tcp: {port: 5000}, serial: {device: /dev/ttyS2}}\n");
    const auto b = plc_config(
        "modbus: {tcp: {port: 5020}, rtu: {device: /dev/ttyS1, parity: N}}\n"
        "fatek: {tcp: {port: 5001, read_only: true}, udp: {port: 5000},\n"
        "        serial: {device: /dev/ttyS2, baud: 19200}}\n");
    EXPECT_EQ(
        daemon::config_changes(a, b),
        (std::vector<std::string>{"modbus.rtu: /dev/ttyS1 9600 8E1 -> /dev/ttyS1 9600 8N1",
                                  "fatek.tcp.port: 5000 -> 5001",
                                  "fatek.tcp.read_only: false -> true", "fatek.udp: off -> on",
                                  "fatek.serial: /dev/ttyS2 9600 7E1 -> /dev/ttyS2 19200 7E1"}));
    EXPECT_TRUE(daemon::config_changes(b, b).empty());
}

// docs/operations.md, "Reload (SIGHUP)": `plant:` key by key; a channel key that only follows a
// changed default is not repeated, one written in the channel is.
TEST(Reload, PlantChangesAreListedKeyByKey) {
    const auto a = plc_config(
        "plant:\n"
        "  defaults: {ambient: 20}\n"
        "  channels: {0: {tau: 120}, 1: {noise: 0.5}, 2: {ambient: 20}}\n");
    const auto b = plc_config(
        "plant:\n"
        "  seed: 7\n"
        "  defaults: {ambient: 30}\n"
        "  channels: {0: {tau: 300, drive: R10, faults: {heater_open: true}}, 2: {ambient: 22},\n"
        "             3: {k: 100}}\n");
    EXPECT_EQ(daemon::config_changes(a, b),
              (std::vector<std::string>{
                  "plant.defaults.ambient: 20 -> 30", "plant.channels.0.tau: 120 -> 300",
                  "plant.channels.0.drive: default -> R10",
                  "plant.channels.0.faults.heater_open: false -> true",
                  "plant.channels.2.ambient: 20 -> 22", "plant.channels.3: added",
                  "plant.channels.1: removed", "plant.seed: 1 -> 7"}));
    EXPECT_TRUE(daemon::config_changes(b, b).empty());
    EXPECT_TRUE(config::plant_changes(a.plant, a.plant, profiles::of(a).naming()).empty());
}

}  // namespace
}  // namespace plcemu
