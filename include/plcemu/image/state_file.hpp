#pragma once
// The state file: the whole register image in one memory-mapped file, so that every value
// written into the image is in the kernel's page cache the moment it is written and survives the
// process being killed at any instant. See docs/operations.md ("Retentive memory") for the format.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <ctime>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "plcemu/image/layout.hpp"

namespace plcemu::image {

/// On-disk header of a state file (little-endian, at offset 0; the image starts at kDataOffset).
struct StateFileHeader {
    char magic[8];                     ///< "PLCEMUST"
    std::uint32_t version;             ///< format version (kStateFileVersion)
    std::uint32_t header_size;         ///< bytes before the image (kDataOffset)
    std::uint32_t profile;             ///< Layout::family
    std::uint32_t area_count;          ///< kAreaCount
    std::uint32_t area_size[16];       ///< devices per area, unused slots 0
    std::uint64_t storage_size;        ///< bytes of the image block
    std::uint64_t layout_checksum;     ///< FNV-1a 64 of profile, area count, sizes, storage size
    std::uint32_t state;               ///< kStateOpen while a process uses it, kStateClosed after
    std::uint32_t retentive_count;     ///< retentive ranges stored after the header fields
    std::uint64_t retentive_checksum;  ///< FNV-1a 64 of the retentive range list
    std::uint64_t data_checksum;       ///< FNV-1a 64 of the image block, valid when closed
    std::uint64_t created;             ///< Unix time the file was created
    std::uint64_t header_checksum;     ///< FNV-1a 64 of the header up to here plus the ranges
};

/// Current format version.
inline constexpr std::uint32_t kStateFileVersion = 1;
/// Offset of the image in the file (one page: the image is page-aligned).
inline constexpr std::size_t kDataOffset = 4096;
/// Retentive ranges a config may list (`persistence.retentive`).
inline constexpr std::size_t kMaxConfiguredRanges = 256;
/// Retentive ranges a header can record: a config's, and those its family keeps whatever the
/// config says (R4057), with room to spare.
inline constexpr std::size_t kMaxRetentiveRanges = kMaxConfiguredRanges + 16;
/// `state` while a process has the file open (a crash leaves it so).
inline constexpr std::uint32_t kStateOpen = 1;
/// `state` after a clean close (the data checksum is then valid).
inline constexpr std::uint32_t kStateClosed = 2;

/// FNV-1a, 64 bits: the checksum of the header, the layout and the data.
std::uint64_t fnv1a64(std::span<const std::byte> bytes, std::uint64_t seed = 0xcbf29ce484222325ULL);

/// One thing opening found or did, for the log.
struct StateNote {
    bool warning = false;  ///< worth a warning (a file moved aside, a crash recovered)
    std::string text;      ///< one line
};

/// How an open state file came to be.
enum class StateOrigin : std::uint8_t {
    Created,    ///< no usable file: a new one, all zero
    Clean,      ///< reopened after a clean close (data checksum verified)
    Recovered,  ///< reopened after a crash or SIGKILL (the page cache had every write)
};

/// One state file, open and mapped (MAP_SHARED), its blocks allocated and `path.lock` held
/// (flock) for as long as it is open. Not thread-safe except sync().
class StateFile {
public:
    /// Takes the lock on `path.lock` first, then opens `path` for `layout` (whose
    /// retentive ranges are recorded), or creates it. A file that is corrupted or does not match
    /// is renamed to `path.bad-YYYYmmdd-HHMMSS` (local time `now`) and a new one created; what
    /// happened is in notes(). Every file of the set (`path`, `path.lock`, `path.new`) is opened
    /// in `path`'s directory without following a symlink as its last component: a `path` or
    /// `path.lock` that is a symlink (or not a regular file) is refused, a `path.new` left over
    /// is removed (a symlink as a link) and created exclusively. Throws std::system_error, naming
    /// `path`, when the lock is held by another process ("in use by another process"), when a
    /// file of the set is a symlink ("is a symbolic link") or not a regular file, when the
    /// file's blocks cannot be reserved ("cannot reserve N bytes", e.g. a full disk), or when it
    /// cannot be created or mapped.
    StateFile(const std::string& path, const Layout& layout, std::time_t now);
    /// Closes cleanly (see close()).
    ~StateFile();
    StateFile(const StateFile&) = delete;
    StateFile& operator=(const StateFile&) = delete;

    /// The image block (page-aligned, `Image::storage_size(layout)` bytes).
    std::span<std::byte> storage() { return storage_; }
    /// The file's path.
    const std::string& path() const { return path_; }
    /// Where the contents came from.
    StateOrigin origin() const { return origin_; }
    /// True when the image holds values from an earlier run (origin is not Created).
    bool retained() const { return origin_ != StateOrigin::Created; }
    /// The retentive ranges the file recorded when it was opened (none when created): the
    /// devices retentive both then and now kept their values, the rest were cleared.
    const std::vector<Range>& retentive_before() const { return retentive_before_; }
    /// What opening found and did (moved aside, recovered, retentive ranges changed…).
    const std::vector<StateNote>& notes() const { return notes_; }
    /// Where a rejected file was moved ("" when none was).
    const std::string& moved_aside() const { return moved_aside_; }

    /// Records new retentive ranges in the header (config reload); the next sync writes every
    /// page.
    void set_retentive(const std::vector<Range>& retentive);
    /// Writes to disk (msync MS_SYNC) every page of the file whose retentive devices or header
    /// changed since it was last written: the first sync, and the first after set_retentive(),
    /// write them all. A page whose only changes are to devices cleared at every start is left
    /// to the kernel's own writeback. Safe from another thread. False when the kernel could not
    /// (an I/O error; those pages stay due and the next sync retries them).
    bool sync() noexcept;
    /// Pages written to disk by sync() so far.
    std::uint64_t pages_synced() const;
    /// False once the file open is no longer the one at its path (deleted, moved away or
    /// replaced while in use): what is synced then is lost at the close. Safe from another
    /// thread.
    bool in_place() const noexcept;
    /// Syncs, stores the data checksum, marks the file closed and unmaps it. Idempotent.
    /// Returns 0, or the errno of a write the disk did not take: the file is then left marked
    /// open, and the next start recovers what the disk holds as after a crash.
    int close() noexcept;

private:
    void open_directory();
    void close_directory() noexcept;
    int open_in_directory(const std::string& name, int flags, const char* what);
    std::string sibling(const std::string& name) const;
    void lock();
    void unlock() noexcept;
    bool try_open(const Layout& layout, std::string& why_bad);
    void create(const Layout& layout, std::time_t now);
    void map(std::size_t size);
    void release() noexcept;
    void move_aside(const std::string& why, std::time_t now);
    void write_header_checksum() noexcept;
    void plan_sync(const std::vector<Range>& retentive);
    void take_plan();
    void sum_pages(std::vector<std::uint64_t>& sums) const noexcept;
    bool sync_pages(std::size_t first, std::size_t end) noexcept;
    void redirty_due() noexcept;
    void redirty(std::size_t page) noexcept;

    // Bytes whose changes must reach the disk within a sync period, each inside one page of
    // the mapping (the header page whole, the retentive ranges' devices), in file order.
    struct Piece {
        std::uint32_t page;
        std::uint32_t offset;
        std::uint32_t size;
    };
    // Where a page stands (due_): unchanged since written, to be written, written just now.
    static constexpr std::uint8_t kClean = 0;
    static constexpr std::uint8_t kDue = 1;
    static constexpr std::uint8_t kWritten = 2;
    Layout layout_;  // the sizes, to place ranges
    // The pieces set_retentive() planned, until sync() takes them.
    std::mutex plan_mutex_;
    std::vector<Piece> planned_;
    bool replanned_ = false;
    // What sync() keeps, per page of the mapping, under sync_mutex_ (held by sync(), on another
    // thread than the rest, and by close()).
    std::mutex sync_mutex_;
    std::vector<Piece> pieces_;            // see Piece
    std::vector<std::uint64_t> synced_;    // the sum of its pieces when it was last written
    std::vector<std::uint64_t> sums_;      // the sums of the sync under way, before its msyncs
    std::vector<std::uint64_t> after_;     // and after them
    std::vector<std::uint8_t> due_;        // kClean, kDue or kWritten
    std::vector<unsigned char> resident_;  // mincore(): bit 0 set when in the page cache
    std::atomic<std::uint64_t> pages_synced_{0};
    bool refused_ = false;  // a write-back failed since the file was opened (sync_mutex_)

    std::string path_;
    std::string name_;  // the last component of path_
    int dir_fd_ = -1;   // path_'s directory, open while the constructor runs
    int lock_fd_ = -1;
    int fd_ = -1;
    std::byte* base_ = nullptr;
    std::size_t mapped_ = 0;
    std::span<std::byte> storage_;
    StateOrigin origin_ = StateOrigin::Created;
    std::vector<StateNote> notes_;
    std::vector<Range> retentive_before_;
    std::string moved_aside_;
};

}  // namespace plcemu::image
