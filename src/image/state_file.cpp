#include "plcemu/image/state_file.hpp"

#include <fcntl.h>
#include <linux/fiemap.h>
#include <linux/fs.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <utility>

// Header-only (inlined): XXH3 sums a page's retentive bytes at memory speed, where FNV-1a's
// byte at a time would cost a tenth of a core at 5,000 PLCs syncing every second.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include "plcemu/image/image.hpp"

namespace plcemu::image {

namespace {

constexpr char kMagic[8] = {'P', 'L', 'C', 'E', 'M', 'U', 'S', 'T'};
constexpr std::size_t kPage = 4096;
// Bytes of the header covered by header_checksum (everything before the field itself).
constexpr std::size_t kHeaderSummed = offsetof(StateFileHeader, header_checksum);
constexpr std::size_t kRangesOffset = sizeof(StateFileHeader);

static_assert(sizeof(StateFileHeader) == 144, "the on-disk header has a fixed size");
static_assert(kRangesOffset + kMaxRetentiveRanges * 12 <= kDataOffset);

struct RangeRecord {
    std::uint32_t area;
    std::uint32_t start;
    std::uint32_t count;
};
static_assert(sizeof(RangeRecord) == 12);

std::size_t round_up(std::size_t n) { return (n + kPage - 1) / kPage * kPage; }

[[noreturn]] void throw_errno(const std::string& what) {
    throw std::system_error(errno, std::generic_category(), what);
}

[[noreturn]] void throw_in_use(const std::string& path) {
    throw std::system_error(
        EWOULDBLOCK, std::generic_category(),
        "state file " + path + " is in use by another process (another plcemud holds its lock)");
}

// Allocates every block of [0, size) so that no later write into the mapping can fault (SIGBUS)
// on a full disk; on blocks already allocated this is cheap and changes nothing.
void reserve(int fd, const std::string& path, std::size_t size) {
    int e = 0;
    do {
        e = ::posix_fallocate(fd, 0, static_cast<off_t>(size));  // returns the error, not errno
    } while (e == EINTR);
    if (e != 0) {
        throw std::system_error(
            e, std::generic_category(),
            "state file " + path + ": cannot reserve " + std::to_string(size) + " bytes");
    }
}

// Writes the file's "unwritten" extents (reserved, never written, read as zeros) with what
// reading them gives, so that every block is an ordinary one (see create()): a file made by an
// earlier version reserved its blocks without writing them, and a sparse one gets them from
// reserve(). What is read is the page cache's, so a page a killed process left dirty there keeps
// its values. Returns true when it wrote any; a file system without FIEMAP has no such extents.
bool write_unwritten(int fd, std::size_t size) {
    constexpr std::size_t kExtents = 32;
    std::vector<std::uint64_t> buf((sizeof(fiemap) + kExtents * sizeof(fiemap_extent)) / 8 + 1);
    auto* map = reinterpret_cast<fiemap*>(buf.data());
    std::vector<std::byte> bytes;
    bool wrote = false;
    for (std::uint64_t start = 0, before = 1; start < size && start != before;) {
        before = start;
        std::fill(buf.begin(), buf.end(), 0);
        map->fm_start = start;
        map->fm_length = size - start;
        map->fm_extent_count = kExtents;
        if (::ioctl(fd, FS_IOC_FIEMAP, map) != 0 || map->fm_mapped_extents == 0) break;
        for (std::uint32_t i = 0; i < map->fm_mapped_extents; ++i) {
            const fiemap_extent& e = map->fm_extents[i];
            const std::uint64_t end = std::min<std::uint64_t>(e.fe_logical + e.fe_length, size);
            if ((e.fe_flags & FIEMAP_EXTENT_UNWRITTEN) != 0 && e.fe_logical < end) {
                bytes.resize(end - e.fe_logical);
                const auto n = static_cast<ssize_t>(bytes.size());
                const auto at = static_cast<off_t>(e.fe_logical);
                if (::pread(fd, bytes.data(), bytes.size(), at) != n ||
                    ::pwrite(fd, bytes.data(), bytes.size(), at) != n) {
                    return wrote;
                }
                wrote = true;
            }
            start = std::max(start, end);
            if ((e.fe_flags & FIEMAP_EXTENT_LAST) != 0) start = size;
        }
    }
    return wrote;
}

std::uint64_t layout_checksum(std::uint32_t profile,
                              std::uint32_t area_count,
                              const std::uint32_t (&sizes)[16],
                              std::uint64_t storage_size) {
    std::byte buf[4 + 4 + 64 + 8];
    std::memcpy(buf, &profile, 4);
    std::memcpy(buf + 4, &area_count, 4);
    std::memcpy(buf + 8, sizes, 64);
    std::memcpy(buf + 72, &storage_size, 8);
    return fnv1a64(buf);
}

std::vector<RangeRecord> records_of(const std::vector<Range>& ranges) {
    std::vector<RangeRecord> v;
    v.reserve(ranges.size());
    for (const auto& r : ranges)
        v.push_back({static_cast<std::uint32_t>(r.area), r.start, r.count});
    return v;
}

std::uint64_t records_checksum(const std::vector<RangeRecord>& v) {
    return fnv1a64(std::as_bytes(std::span(v)));
}

// The header a layout calls for (state, checksums of data and header left to the caller).
StateFileHeader expected_header(const Layout& layout) {
    StateFileHeader h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.version = kStateFileVersion;
    h.header_size = kDataOffset;
    h.profile = layout.family;
    h.area_count = kAreaCount;
    for (std::size_t i = 0; i < kAreaCount; ++i) h.area_size[i] = layout.size[i];
    h.storage_size = Image::storage_size(layout);
    h.layout_checksum = layout_checksum(h.profile, h.area_count, h.area_size, h.storage_size);
    return h;
}

std::string describe_layout_difference(const StateFileHeader& file,
                                       const StateFileHeader& want,
                                       const Layout& layout) {
    if (file.profile != want.profile) {
        const std::string_view name =
            layout.name_of_family != nullptr ? layout.name_of_family(file.profile) : "";
        std::string s = "it holds the image of another PLC family (";
        if (name.empty()) {
            s += "number ";
            s += std::to_string(file.profile);
        } else {
            s += name;
        }
        s += "), not of ";
        s += layout.family_name;
        return s;
    }
    if (file.area_count != want.area_count) {
        return "it has " + std::to_string(file.area_count) + " device areas, not " +
               std::to_string(want.area_count);
    }
    for (std::size_t i = 0; i < kAreaCount; ++i) {
        if (file.area_size[i] != want.area_size[i]) {
            return "its " + std::string(area_name(static_cast<Area>(i))) + " area has " +
                   std::to_string(file.area_size[i]) + " devices, not " +
                   std::to_string(want.area_size[i]);
        }
    }
    if (file.storage_size != want.storage_size) {
        return "its image is " + std::to_string(file.storage_size) + " bytes, not " +
               std::to_string(want.storage_size);
    }
    return "its layout checksum differs";
}

std::string timestamp(std::time_t now) {
    std::tm tm{};
    localtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
    return buf;
}

}  // namespace

std::uint64_t fnv1a64(std::span<const std::byte> bytes, std::uint64_t seed) {
    std::uint64_t h = seed;
    for (std::byte b : bytes) {
        h ^= static_cast<std::uint64_t>(b);
        h *= 0x100000001b3ULL;
    }
    return h;
}

StateFile::StateFile(const std::string& path, const Layout& layout, std::time_t now)
    : layout_(layout),
      path_(path) {
    if (layout.retentive.size() > kMaxRetentiveRanges) {
        throw std::invalid_argument("state file: at most " + std::to_string(kMaxRetentiveRanges) +
                                    " retentive ranges");
    }
    try {
        open_directory();
        lock();
        std::string why;
        if (try_open(layout, why)) {
            set_retentive(layout.retentive);
        } else {
            if (!why.empty()) move_aside(why, now);
            try {
                create(layout, now);
            } catch (const std::system_error& e) {
                // The move is said with the failure: no note is logged when the start stops.
                if (moved_aside_.empty()) throw;
                std::string what = e.what();
                what.append(" (the damaged file was moved to ").append(moved_aside_);
                what.append(" first: ").append(why).append(")");
                throw std::runtime_error(what);
            }
        }
    } catch (...) {
        release();
        unlock();
        close_directory();
        throw;
    }
    close_directory();
    if (origin_ == StateOrigin::Created) return;  // made "open", its ranges recorded, on disk
    StateFileHeader h;
    std::memcpy(&h, base_, sizeof h);
    h.state = kStateOpen;
    std::memcpy(base_, &h, sizeof h);
    write_header_checksum();
    // The header says "open" on disk before anything else happens, so a crash is recognised.
    ::msync(base_, kPage, MS_SYNC);
}

StateFile::~StateFile() { close(); }

void StateFile::open_directory() {
    // Every file of the set is reached through this one descriptor, by a name without a slash:
    // the directory may be reached through symlinks, but it stays the same directory throughout,
    // and no final component is ever followed (O_NOFOLLOW, docs/operations.md).
    const auto slash = path_.rfind('/');
    const std::string dir = slash == std::string::npos ? "." : path_.substr(0, slash + 1);
    name_ = slash == std::string::npos ? path_ : path_.substr(slash + 1);
    if (name_.empty() || name_ == "." || name_ == "..") {
        throw std::system_error(EISDIR, std::generic_category(),
                                "state file " + path_ + ": names a directory, not a file");
    }
    dir_fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir_fd_ < 0) throw_errno("state file " + path_ + ": cannot open its directory " + dir);
}

void StateFile::close_directory() noexcept {
    if (dir_fd_ >= 0) ::close(dir_fd_);
    dir_fd_ = -1;
}

int StateFile::open_in_directory(const std::string& name, int flags, const char* what) {
    // O_NONBLOCK: a FIFO planted under the name must not hold the start; O_NOCTTY: nor may a
    // terminal planted there become the daemon's. Both are refused below.
    const int fd = ::openat(dir_fd_, name.c_str(),
                            flags | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC, 0600);
    if (fd < 0) {
        if (errno == ELOOP) {
            throw std::system_error(
                ELOOP, std::generic_category(),
                "state file " + path_ + ": " + what + " " + sibling(name) +
                    " is a symbolic link, which plcemud never follows (remove it, or set "
                    "persistence.file to the real path)");
        }
        return -1;
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        throw std::system_error(
            EINVAL, std::generic_category(),
            "state file " + path_ + ": " + what + " " + sibling(name) + " is not a regular file");
    }
    return fd;
}

std::string StateFile::sibling(const std::string& name) const {
    return path_.substr(0, path_.size() - name_.size()) + name;
}

void StateFile::lock() {
    const std::string lock_name = name_ + ".lock";
    // Never truncated, renamed or mapped, unlike the state file and its `.new`: locking it first
    // makes everything after (checks, moving aside, creating) one process's alone.
    lock_fd_ = open_in_directory(lock_name, O_RDONLY | O_CREAT, "its lock");
    if (lock_fd_ < 0) {
        throw_errno("state file " + path_ + ": cannot open its lock " + sibling(lock_name));
    }
    if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EWOULDBLOCK) throw_in_use(path_);
        throw_errno("state file " + path_ + ": cannot lock " + sibling(lock_name));
    }
}

void StateFile::unlock() noexcept {
    if (lock_fd_ >= 0) ::close(lock_fd_);
    lock_fd_ = -1;
}

bool StateFile::try_open(const Layout& layout, std::string& why_bad) {
    fd_ = open_in_directory(name_, O_RDWR, "the file");
    if (fd_ < 0) {
        if (errno == ENOENT) return false;
        throw_errno("state file " + path_ + ": cannot open");
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        const int e = errno;
        ::close(fd_);
        fd_ = -1;
        if (e == EWOULDBLOCK) throw_in_use(path_);
        throw std::system_error(e, std::generic_category(),
                                "state file " + path_ + ": cannot lock");
    }
    auto reject = [&](std::string why) {
        why_bad = std::move(why);
        release();
        return false;
    };

    struct stat st {};
    if (::fstat(fd_, &st) != 0) throw_errno("state file " + path_ + ": cannot stat");
    const auto file_size = static_cast<std::size_t>(st.st_size);
    StateFileHeader h{};
    if (file_size < kDataOffset) {
        return reject("corrupted: truncated to " + std::to_string(file_size) + " bytes");
    }
    if (::pread(fd_, &h, sizeof h, 0) != static_cast<ssize_t>(sizeof h)) {
        return reject("corrupted: cannot read its header");
    }
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) {
        return reject("corrupted: not a plcemu state file (bad magic)");
    }
    if (h.retentive_count > kMaxRetentiveRanges) {
        return reject("corrupted: bad retentive range count " + std::to_string(h.retentive_count));
    }
    std::vector<RangeRecord> old(h.retentive_count);
    const auto ranges_bytes = static_cast<ssize_t>(old.size() * sizeof(RangeRecord));
    if (::pread(fd_, old.data(), old.size() * sizeof(RangeRecord), kRangesOffset) != ranges_bytes) {
        return reject("corrupted: cannot read its retentive ranges");
    }
    std::uint64_t sum = fnv1a64(std::as_bytes(std::span(&h, 1)).first(kHeaderSummed));
    sum = fnv1a64(std::as_bytes(std::span(old)), sum);
    if (sum != h.header_checksum) return reject("corrupted: header checksum mismatch");
    if (h.version != kStateFileVersion) {
        return reject("does not match: format version " + std::to_string(h.version) +
                      ", this plcemud reads version " + std::to_string(kStateFileVersion));
    }
    if (h.header_size != kDataOffset) return reject("corrupted: bad header size");
    const StateFileHeader want = expected_header(layout);
    if (h.profile != want.profile || h.area_count != want.area_count ||
        std::memcmp(h.area_size, want.area_size, sizeof want.area_size) != 0 ||
        h.storage_size != want.storage_size || h.layout_checksum != want.layout_checksum) {
        return reject("does not match the configuration: " +
                      describe_layout_difference(h, want, layout));
    }
    if (records_checksum(old) != h.retentive_checksum) {
        return reject("corrupted: retentive range checksum mismatch");
    }
    if (file_size < kDataOffset + h.storage_size) {
        return reject("corrupted: truncated to " + std::to_string(file_size) + " bytes");
    }
    // Created at exactly this size and never grown: anything after the image was written by
    // something else, so the rest cannot be trusted either.
    const std::size_t whole = kDataOffset + round_up(h.storage_size);
    if (file_size > whole) {
        return reject("corrupted: " + std::to_string(file_size - whole) +
                      " bytes after the image (" + std::to_string(file_size) + " bytes, not " +
                      std::to_string(whole) + ")");
    }
    if (h.state != kStateOpen && h.state != kStateClosed) {
        return reject("corrupted: bad state " + std::to_string(h.state));
    }
    // A file from before blocks were reserved may be sparse: a full disk is then an error now.
    reserve(fd_, path_, kDataOffset + round_up(h.storage_size));
    // Blocks reserved but never written are written now, once (on the disk before the PLC runs).
    if (write_unwritten(fd_, kDataOffset + round_up(h.storage_size)) && ::fdatasync(fd_) != 0) {
        throw_errno("state file " + path_ + ": cannot sync");
    }
    map(kDataOffset + round_up(h.storage_size));
    if (h.state == kStateClosed && fnv1a64(storage_) != h.data_checksum) {
        return reject("corrupted: data checksum mismatch (closed cleanly, changed since)");
    }
    if (h.state == kStateClosed) {
        origin_ = StateOrigin::Clean;
        notes_.push_back({false, "state file " + path_ + ": reopened (closed cleanly last time)"});
    } else {
        origin_ = StateOrigin::Recovered;
        notes_.push_back({true, "state file " + path_ +
                                    ": its last user did not close it (crash, SIGKILL, power "
                                    "loss, or a last sync the disk refused); values are those "
                                    "the kernel had"});
    }

    // Only devices retentive both then and now keep their values: the rest held live data when
    // the file was last used, which nobody asked to keep.
    std::vector<Range> before;
    for (const auto& r : old) {
        if (r.area >= kAreaCount) return reject("corrupted: bad retentive range");
        before.push_back({static_cast<Area>(r.area), r.start, r.count});
    }
    retentive_before_ = before;
    if (!same_devices(before, layout.retentive)) {
        Layout then = layout;
        then.retentive = before;
        Image(then, storage_).clear_non_retentive(before);
        notes_.push_back({true, "state file " + path_ +
                                    ": the retentive ranges changed; only devices retentive "
                                    "before and now keep their values"});
    }
    return true;
}

void StateFile::create(const Layout& layout, std::time_t now) {
    // Under the lock (see lock()), so nobody else has `.new` open: a leftover is a dead creator's.
    // It is removed (unlink never follows a link: a planted symlink goes, its target stays) and
    // made anew exclusively, so the image is written into no file but a new one of our own.
    const std::string tmp_name = name_ + ".new";
    const std::string tmp = sibling(tmp_name);
    struct stat st {};
    if (::fstatat(dir_fd_, tmp_name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0) {
        if (::unlinkat(dir_fd_, tmp_name.c_str(), 0) != 0)
            throw_errno("state file " + tmp + ": cannot remove a leftover");
        if (S_ISLNK(st.st_mode)) {
            notes_.push_back({true, "state file " + path_ + ": its temporary " + tmp +
                                        " was a symbolic link; removed the link (not followed, "
                                        "its target untouched)"});
        }
    }
    fd_ = open_in_directory(tmp_name, O_RDWR | O_CREAT | O_EXCL, "its temporary");
    if (fd_ < 0) throw_errno("state file " + tmp + ": cannot create");
    try {
        if (::flock(fd_, LOCK_EX | LOCK_NB) != 0)
            throw_errno("state file " + tmp + ": cannot lock");
        StateFileHeader h = expected_header(layout);
        h.state = kStateOpen;
        h.created = static_cast<std::uint64_t>(now);
        const std::size_t total = kDataOffset + round_up(h.storage_size);
        reserve(fd_, path_, total);  // also sizes the file
        // Every block written once, not only reserved: ext4 keeps a reserved block "unwritten"
        // (read as zeros) until a write of it completes, and a block whose first write-back
        // failed (a disk refusing writes) stays so even after later writes of it succeed, so
        // the values synced into it would read back as zeros after a reboot
        // (tests/system/test_state_write_errors.py). Written now, it is an ordinary block.
        std::vector<std::byte> whole(total);
        std::memcpy(whole.data(), &h, sizeof h);
        if (::pwrite(fd_, whole.data(), total, 0) != static_cast<ssize_t>(total)) {
            throw_errno("state file " + tmp + ": cannot write");
        }
        map(total);
        set_retentive(layout.retentive);  // the header whole, its checksum too
        // Whole and on disk under its temporary name before it takes the real one (fsync
        // writes the mapping's changed pages as well: one flush of the disk, not two).
        if (::fsync(fd_) != 0) {
            throw_errno("state file " + tmp + ": cannot sync");
        }
        if (::renameat(dir_fd_, tmp_name.c_str(), dir_fd_, name_.c_str()) != 0)
            throw_errno("state file " + path_ + ": cannot create");
    } catch (...) {
        // A half-made file is of no use to anyone: do not leave it behind.
        release();
        ::unlinkat(dir_fd_, tmp_name.c_str(), 0);
        throw;
    }
    // The rename (and a move aside before it) on disk too.
    ::fsync(dir_fd_);
    origin_ = StateOrigin::Created;
    notes_.push_back({false, "state file " + path_ + ": created"});
}

void StateFile::release() noexcept {
    if (base_) ::munmap(base_, mapped_);
    base_ = nullptr;
    mapped_ = 0;
    storage_ = {};
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

void StateFile::map(std::size_t size) {
    void* p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
    if (p == MAP_FAILED) throw_errno("state file " + path_ + ": cannot map");
    base_ = static_cast<std::byte*>(p);
    mapped_ = size;
    StateFileHeader h;
    std::memcpy(&h, base_, sizeof h);
    storage_ = std::span<std::byte>(base_ + kDataOffset, h.storage_size);
}

void StateFile::move_aside(const std::string& why, std::time_t now) {
    std::string target = name_ + ".bad-" + timestamp(now);
    struct stat st {};
    for (int n = 1; ::fstatat(dir_fd_, target.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0; ++n) {
        target = name_ + ".bad-" + timestamp(now) + "-" + std::to_string(n);
    }
    if (::renameat(dir_fd_, name_.c_str(), dir_fd_, target.c_str()) != 0) {
        throw_errno("state file " + path_ + " " + why + ", and it cannot be moved aside");
    }
    target = sibling(target);
    moved_aside_ = target;
    notes_.push_back({true, "state file " + path_ + " " + why + "; moved to " + target +
                                ", starting with a fresh one"});
}

void StateFile::set_retentive(const std::vector<Range>& retentive) {
    if (!base_) return;
    if (retentive.size() > kMaxRetentiveRanges) {
        throw std::invalid_argument("state file: at most " + std::to_string(kMaxRetentiveRanges) +
                                    " retentive ranges");
    }
    const auto rec = records_of(retentive);
    StateFileHeader h;
    std::memcpy(&h, base_, sizeof h);
    h.retentive_count = static_cast<std::uint32_t>(rec.size());
    h.retentive_checksum = records_checksum(rec);
    std::memcpy(base_, &h, sizeof h);
    if (!rec.empty()) std::memcpy(base_ + kRangesOffset, rec.data(), rec.size() * sizeof rec[0]);
    write_header_checksum();
    plan_sync(retentive);
}

void StateFile::plan_sync(const std::vector<Range>& retentive) {
    // The bytes a power loss must not lose, as spans of the mapping, merged where they meet.
    std::vector<std::pair<std::size_t, std::size_t>> spans{{0, kDataOffset}};  // the header
    for (const auto& r : retentive) {
        const auto e = Image::extent(layout_, r);
        if (e.size > 0) spans.emplace_back(kDataOffset + e.offset, kDataOffset + e.offset + e.size);
    }
    std::sort(spans.begin(), spans.end());
    std::vector<Piece> pieces;
    std::size_t done = 0;  // bytes before this are already in a piece
    for (auto [begin, end] : spans) {
        begin = std::max(begin, done);
        end = std::min(end, mapped_);
        for (std::size_t at = begin; at < end;) {
            const std::size_t page = at / kPage;
            const std::size_t stop = std::min(end, (page + 1) * kPage);
            if (!pieces.empty() && pieces.back().page == page &&
                pieces.back().offset + pieces.back().size == at) {
                pieces.back().size += static_cast<std::uint32_t>(stop - at);
            } else {
                pieces.push_back({static_cast<std::uint32_t>(page), static_cast<std::uint32_t>(at),
                                  static_cast<std::uint32_t>(stop - at)});
            }
            at = stop;
        }
        done = std::max(done, end);
    }
    // Handed over under a lock of its own: a reload on the loop never waits for a sync's msync.
    std::lock_guard lock(plan_mutex_);
    planned_ = std::move(pieces);
    replanned_ = true;
}

void StateFile::take_plan() {
    std::lock_guard lock(plan_mutex_);
    if (!replanned_) return;
    pieces_ = std::move(planned_);
    replanned_ = false;
    const std::size_t pages = mapped_ / kPage;
    synced_.assign(pages, 0);
    sums_.assign(pages, 0);
    after_.assign(pages, 0);
    due_.assign(pages, kDue);
    resident_.assign(pages, 1);
}

void StateFile::write_header_checksum() noexcept {
    StateFileHeader h;
    std::memcpy(&h, base_, sizeof h);
    std::uint64_t sum = fnv1a64(std::span<const std::byte>(base_, kHeaderSummed));
    sum = fnv1a64(
        std::span<const std::byte>(base_ + kRangesOffset, h.retentive_count * sizeof(RangeRecord)),
        sum);
    h.header_checksum = sum;
    std::memcpy(base_, &h, sizeof h);
}

bool StateFile::sync() noexcept {
    // Every scan rewrites devices that are cleared at every start anyway (the clock registers,
    // the special relays) on the same pages as retentive ones. Writing a page back write-protects
    // it, which costs an interrupt on every core running the daemon and a fault at the next
    // write into it: only pages whose retentive bytes changed are worth that (docs/performance.md,
    // "The sync thread"). The rest reach the disk by the kernel's writeback, and nobody reads them
    // after a power loss: they are cleared at the next start.
    std::lock_guard lock(sync_mutex_);
    if (base_ == nullptr) return true;
    take_plan();
    // The loop writes into the mapping meanwhile, as it did while the kernel read it for msync:
    // a sum taken across a write differs from both sides of it, and its page is written.
    // A page outside the page cache cannot be dirty (a dirty page is written before it is
    // dropped), and reading it to sum it would bring it in: pages of retentive devices nobody
    // has used stay on the disk alone. One still due is written once it is back.
    if (::mincore(base_, mapped_, resident_.data()) != 0)
        std::fill(resident_.begin(), resident_.end(), 1);
    sum_pages(sums_);
    const std::size_t pages = sums_.size();
    for (std::size_t p = 0; p < pages; ++p) {
        if ((resident_[p] & 1) != 0 && sums_[p] != synced_[p]) due_[p] = kDue;
    }
    const auto writable = [this](std::size_t p) {
        return due_[p] == kDue && (resident_[p] & 1) != 0;
    };
    bool ok = true;
    for (std::size_t first = 0; first < pages;) {
        if (!writable(first)) {
            ++first;
            continue;
        }
        std::size_t end = first + 1;
        while (end < pages && writable(end)) ++end;
        if (sync_pages(first, end)) {
            std::fill(due_.begin() + static_cast<std::ptrdiff_t>(first),
                      due_.begin() + static_cast<std::ptrdiff_t>(end), kWritten);
        } else {
            ok = false;
        }
        first = end;
    }
    if (!ok) {
        redirty_due();
        refused_ = true;
    }
    // A written page is known to hold the sums taken before its msync only when they are the
    // same after it: after a change during the msync, which may or may not be on the disk, the
    // page stays due.
    sum_pages(after_);
    for (std::size_t p = 0; p < pages; ++p) {
        if (due_[p] != kWritten) continue;
        synced_[p] = sums_[p];
        due_[p] = sums_[p] == after_[p] ? kClean : kDue;
    }
    return ok;
}

// A write-back that failed leaves its pages clean in the page cache: the kernel reports the
// error once (to the msync that finds it, whichever range that msync was given) and writes those
// pages again only if they are written to again. Every page this sync was to write is made dirty
// once more and stays due, so the next sync writes it for real; one whose msync returned 0 in
// the same sync may have lost its write to the error another range reported. The page's bytes
// are left as they are (see redirty()).
void StateFile::redirty_due() noexcept {
    for (std::size_t p = 0; p < due_.size(); ++p) {
        if (due_[p] == kClean || (resident_[p] & 1) == 0) continue;
        due_[p] = kDue;
        redirty(p);
    }
}

void StateFile::redirty(std::size_t page) noexcept {
    // A compare-exchange of the byte with itself: a write (the page faults and is marked dirty)
    // that leaves whatever the loop writes into the byte meanwhile, retried until it holds. Not
    // an atomic OR of 0: clang compiles that to a plain load, which dirties nothing.
    auto* byte = reinterpret_cast<unsigned char*>(base_ + page * kPage);
    unsigned char seen = __atomic_load_n(byte, __ATOMIC_RELAXED);
    while (!__atomic_compare_exchange_n(byte, &seen, seen, false, __ATOMIC_RELAXED,
                                        __ATOMIC_RELAXED)) {
    }
}

void StateFile::sum_pages(std::vector<std::uint64_t>& sums) const noexcept {
    std::fill(sums.begin(), sums.end(), 0);
    for (const auto& p : pieces_) {
        if ((resident_[p.page] & 1) != 0)
            sums[p.page] = XXH3_64bits_withSeed(base_ + p.offset, p.size, sums[p.page]);
    }
}

bool StateFile::sync_pages(std::size_t first, std::size_t end) noexcept {
    if (::msync(base_ + first * kPage, (end - first) * kPage, MS_SYNC) != 0) return false;
    pages_synced_.fetch_add(end - first, std::memory_order_relaxed);
    return true;
}

bool StateFile::in_place() const noexcept {
    if (fd_ < 0) return true;
    struct stat held {};
    struct stat there {};
    if (::fstat(fd_, &held) != 0) return true;
    if (held.st_nlink == 0) return false;
    // Renamed or replaced: the path names another file, or none, or a link (which a start never
    // follows, even to this file).
    if (::lstat(path_.c_str(), &there) != 0) return errno != ENOENT;
    return held.st_dev == there.st_dev && held.st_ino == there.st_ino;
}

std::uint64_t StateFile::pages_synced() const {
    return pages_synced_.load(std::memory_order_relaxed);
}

int StateFile::close() noexcept {
    if (fd_ < 0) {
        unlock();
        return 0;
    }
    int error = 0;
    if (base_) {
        std::lock_guard lock(sync_mutex_);  // not while a sync() reads the mapping
        // The image first, the header marked closed after it: a file is marked closed only when
        // the disk took every page. A write-back that failed, now or since the last sync, is
        // reported by this msync; the header then stays "open", and the next start recovers
        // the file as after a crash (what the disk holds) instead of finding its checksum wrong
        // and moving the whole file aside. After a refused write-back any page may be one the
        // kernel marked clean unwritten (one the sync thread does not write: only devices
        // cleared at each start changed there), and the checksum covers them all: every page
        // is written again.
        if (refused_) {
            for (std::size_t p = 0; p < mapped_ / kPage; ++p) redirty(p);
        }
        if (::msync(base_, mapped_, MS_SYNC) != 0) error = errno;
        if (error == 0) {
            StateFileHeader h;
            std::memcpy(&h, base_, sizeof h);
            h.data_checksum = fnv1a64(storage_);
            h.state = kStateClosed;
            std::memcpy(base_, &h, sizeof h);
            write_header_checksum();
            if (::msync(base_, kPage, MS_SYNC) != 0) error = errno;
        }
        ::munmap(base_, mapped_);
        base_ = nullptr;
        mapped_ = 0;
        storage_ = {};
    }
    if (::fsync(fd_) != 0 && error == 0) error = errno;
    ::close(fd_);
    fd_ = -1;
    // Last: the next daemon may have the file only once it is closed and on disk.
    unlock();
    return error;
}

}  // namespace plcemu::image
