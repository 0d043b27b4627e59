#pragma once
// The configuration as plain values: what a YAML file says, validated, with positions kept for
// the errors that later stages (instruction binding) may still find.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plcemu/config/cidr.hpp"
#include "plcemu/config/comm_faults.hpp"
#include "plcemu/config/node.hpp"
#include "plcemu/config/reader.hpp"
#include "plcemu/image/area.hpp"
#include "plcemu/image/excerpt.hpp"
#include "plcemu/image/layout.hpp"
#include "plcemu/image/naming.hpp"
#include "plcemu/plant/channel.hpp"

namespace plcemu::config {

class ProfileSettings;  // family.hpp

/// A scalar operand of an instruction as written ("R100", "0", "K10"), with its position.
struct Operand {
    std::string text;  ///< the scalar as written
    Position pos;      ///< where it stands
};

/// One `program:` entry, e.g. `TPCTL: {en: M0, ...}`.
struct InstructionConfig {
    std::string mnemonic;                                   ///< "MOV", "TPCTL", …
    Position pos;                                           ///< position of the mnemonic
    std::vector<std::pair<std::string, Operand>> operands;  ///< in file order
};

/// One line of a program written in the family's instruction list (`program: {file: oven.il}`
/// or `program: {il: [...]}`), and where it starts.
struct ListingLineConfig {
    std::string text;  ///< the line as written
    Position pos;      ///< where its first character stands
};

/// One `init:` entry: values written from a device upward at start.
struct InitEntry {
    image::Device device;               ///< first device
    std::vector<std::uint16_t> values;  ///< words (or bits as 0/1 for bit devices)
    Position pos;                       ///< position of the key

    /// Devices per value: 16 for a word of bits (WM800), else 1.
    std::uint32_t step() const { return device.word_of_bits ? 16 : 1; }
    /// The devices its values reach.
    image::Range range() const {
        return {device.area, device.index, static_cast<std::uint32_t>(values.size()) * step()};
    }
};

/// What to do with a TCP request for a unit ID that is neither the station nor 255.
enum class UnknownUnit : std::uint8_t { Exception, Silent };

/// `modbus.tcp`
struct TcpConfig {
    bool enabled = true;           ///< serve TCP at all
    std::string bind = "0.0.0.0";  ///< address to listen on
    std::uint16_t port = 502;      ///< port (502 as on a real PLC)
    UnknownUnit unknown_unit =
        UnknownUnit::Exception;   ///< unit-ID policy (docs/profile-fbs.md, "Modbus map")
    std::vector<Cidr> allow;      ///< the allow list (empty = all)
    int max_clients = 64;         ///< concurrent connections
    int idle_timeout_s = 0;       ///< no request this long: close (0 = never)
    int frame_timeout_ms = 5000;  ///< a begun request must be whole, and replies taken, by then
    /// Nothing may be changed through this listener (FATEK listeners; Modbus has
    /// modbus.read_only for all of its listeners).
    bool read_only = false;
    /// `http.token`: the bearer token every write through the console and API must carry
    /// (empty: none).
    std::string token;
    /// `http.hosts`: host names the console answers to besides IP addresses and `localhost`.
    std::vector<std::string> hosts;
};

/// `modbus.rtu` (absent = no serial port)
struct RtuConfig {
    std::string device;  ///< e.g. /dev/ttyUSB0
    int baud = 9600;     ///< bits per second
    char parity = 'E';   ///< 'N', 'E' or 'O'
    int data_bits = 8;   ///< 7 or 8
    int stop_bits = 1;   ///< 1 or 2
    /// Nothing may be changed through this line (FATEK lines; Modbus has modbus.read_only).
    bool read_only = false;
    /// The line hands back what the PLC sends (an RS-485 adapter with local echo): each
    /// answer's echo is read and dropped (a PLC's lines only, not the MBUS master's).
    bool echo = false;
};

/// The Modbus table of a `modbus.map` row.
enum class MapTable : std::uint8_t { Coils, DiscreteInputs, Holding, Input };

/// One `modbus.map` row: `{table: holding, start: 0, device: D0, count: 8000, access: ro}`.
struct MapRowConfig {
    MapTable table = MapTable::Holding;  ///< the Modbus table
    std::uint16_t start = 0;             ///< first wire address
    image::Device device;                ///< first device (WM0: 16 bits per register)
    std::uint16_t count = 0;             ///< elements (registers for a W device)
    bool read_only = false;              ///< `access: ro`
    std::string text;                    ///< the device as written, for --print-map
    Position pos;                        ///< where the row stands
};

/// `modbus`
struct ModbusConfig {
    TcpConfig tcp;                            ///< TCP listener
    std::optional<RtuConfig> rtu;             ///< serial slave
    bool read_only = false;                   ///< refuse every write with exception 02
    std::vector<image::Range> write_protect;  ///< device ranges writes may not touch
    /// `modbus.map`: when present, replaces the profile's default map entirely.
    std::optional<std::vector<MapRowConfig>> map;
};

/// `fatek` (FATEK's own protocol, docs/profile-fbs.md, "FATEK protocol"): each listener is off
/// unless its key is present.
struct FatekConfig {
    std::optional<TcpConfig> tcp;     ///< `fatek.tcp`, port 500 by default
    std::optional<TcpConfig> udp;     ///< `fatek.udp`, port 500 by default
    std::optional<RtuConfig> serial;  ///< `fatek.serial`, 9600 7E1 by default
};

/// A plant channel's fault switches and process parameters: the plant's own values.
using Faults = plant::Faults;
using ChannelParams = plant::ChannelParams;

/// One simulated process channel (docs/simulator-and-plant.md).
struct ChannelConfig {
    ChannelParams params;                 ///< ambient, k, tau, dead_time, noise, cooling,
                                          ///< lead_resistance
    std::optional<image::Device> drive;   ///< Y (PWM duty) or a register; default: the output
                                          ///< the program declares for this channel
    std::optional<int> drive_full_scale;  ///< a register drive's value for full power (default:
                                          ///< the profile's)
    Faults faults;                        ///< initial faults
};

/// `plant`
struct PlantConfig {
    ChannelConfig defaults;                               ///< applied to every channel
    std::vector<std::pair<int, ChannelConfig>> channels;  ///< per-channel overrides
    std::uint64_t seed = 1;                               ///< noise seed (deterministic)
};

/// What differs between two `plant:` sections, one line per key as a reload logs it, in config
/// order: "plant.seed: 1 -> 2", "plant.defaults.tau: 120 -> 60", "plant.channels.3.drive:
/// default -> D10", "plant.channels.5: added" / "removed". Devices are written in `naming`'s
/// notation. A channel's key that only follows a changed `defaults` key is not repeated.
std::vector<std::string> plant_changes(const PlantConfig& before,
                                       const PlantConfig& after,
                                       const image::Naming& naming);

/// `simulator`
struct SimulatorConfig {
    int unit = 247;  ///< Modbus unit of the simulator-control registers (0 = none)
    /// Writes to the unit: by default as modbus.read_only allows (read-only gateway: none).
    std::optional<bool> writable;
};

/// When `init:` presets reach retentive devices.
enum class InitPolicy : std::uint8_t {
    Fresh,   ///< only when the state file is new: retained values win over presets
    Always,  ///< at every start and reload: presets win over retained values
};

/// `persistence`
struct PersistenceConfig {
    bool enabled = true;                                 ///< keep the image in a state file at all
    std::string file;                                    ///< state file ("" = default location)
    std::optional<std::vector<image::Range>> retentive;  ///< overrides the profile's ranges
    int sync_ms = 1000;                                  ///< msync period
    InitPolicy init = InitPolicy::Fresh;                 ///< presets on retentive devices
};

/// `log`
struct LogConfig {
    std::string level = "info";  ///< trace, debug, info, warn, error
};

/// A whole configuration.
/// A sum of what a PLC's config was read from (config/fingerprint.hpp): equal sums, the same PLC.
struct Fingerprint {
    std::uint64_t low = 0;   ///< the sum's low half
    std::uint64_t high = 0;  ///< its high half
    bool operator==(const Fingerprint&) const = default;
};

struct Config {
    std::string path;  ///< file it was read from
    std::string name;  ///< `name:` of a `plcs:` entry
    /// How messages name a `plcs:` entry: "plcs[0]" or "plcs[0] (kiln)"; empty for a file
    /// holding one PLC.
    std::string label;
    int index = -1;                          ///< position in `plcs:`; -1 for a file holding one PLC
    std::string profile;                     ///< PLC family (a registered profile's name)
    std::string model;                       ///< model name (the profile's default)
    std::uint8_t station = 1;                ///< station number
    int scan_ms = 10;                        ///< scan period
    double time_scale = 1.0;                 ///< simulated seconds per real second
    ModbusConfig modbus;                     ///< transports and access
    FatekConfig fatek;                       ///< FATEK's protocol (families that speak it)
    std::optional<TcpConfig> http;           ///< `http:`, the console and REST API (off: absent)
    std::vector<InitEntry> init;             ///< presets
    std::vector<InstructionConfig> program;  ///< ordered instruction list
    /// The program as the family's instruction list instead (docs/program-language.md); empty
    /// when `program:` is a list of entries.
    std::vector<ListingLineConfig> listing;
    /// The sections the profile reads itself (Family::sections), as written.
    std::vector<std::pair<std::string, Node>> sections;
    /// Those sections as the family read them at load (Family::read); null in a Config built
    /// without the loader, or for a family without sections.
    std::shared_ptr<const ProfileSettings> settings;
    PlantConfig plant;              ///< thermal plant
    CommFaultSettings faults;       ///< communication faults from start-up (`faults:`)
    SimulatorConfig simulator;      ///< simulator-control unit
    PersistenceConfig persistence;  ///< retentive state file
    LogConfig log;                  ///< logging
    /// What the loader read it from, summed; a reload leaves running untouched a PLC whose sum is
    /// unchanged (docs/operations.md, "Reload"). Zero in a Config built without the loader.
    Fingerprint fingerprint;
};

/// What the command line sets in every PLC's config (`--port`, `--http-port`, `--time-scale`).
/// The loader applies them to each PLC as it reads it, before it checks the listeners against
/// each other: ports an override makes equal are refused, or shared only where the PLCs agree,
/// exactly as if the file said so.
struct Overrides {
    std::optional<std::uint16_t> port;       ///< modbus.tcp.port
    std::optional<std::uint16_t> http_port;  ///< http.port; a console on 127.0.0.1 where none
    std::optional<double> time_scale;        ///< time_scale
};

/// Applies the overrides to one PLC's config.
void apply(const Overrides& overrides, Config& config);

/// Reads a serial line's settings (`modbus.rtu`, or a profile's own port) into `rtu`; `what`
/// names the key in errors; `slave`: a line the PLC answers on, which may say `echo`. Throws
/// ConfigError.
void read_rtu(const Reader& r, const Node& n, RtuConfig& rtu, const std::string& what, bool slave);

/// Why a device range is refused on a PLC: "D8000 does not exist on this PLC (…)" or "R9000 is
/// outside this PLC's R area (8072 devices)".
std::string outside(const image::Naming& naming,
                    const image::Layout& layout,
                    const image::Range& range);

/// Reads and validates a config file holding one PLC. A file with `plcs:` is refused (it needs
/// load_plcs). Throws ConfigError naming file, line and column.
Config load_config(const std::string& path);

/// Reads and validates a config file holding one PLC or, under `plcs:`, several: one Config per
/// PLC, in file order. Throws ConfigError naming file, line and column (and the entry).
std::vector<Config> load_plcs(const std::string& path, const Overrides& overrides = {});

/// The same for config text; `name` is used in error positions.
std::vector<Config> parse_plcs(const std::string& text,
                               const std::string& name,
                               const Overrides& overrides = {});

/// How machine-readable output names a `plcs:` entry (the `plc` column of `--print-map --format
/// csv` and of `--export-tags`, the prefix of its exported tag names): its `name:`, or "plcs[2]"
/// without one; empty for a file holding one PLC.
std::string plc_id(const Config& config);

/// The state file's name when `persistence.file` is not given: the config file's stem, and for
/// a `plcs:` entry its name (or index) too: "plant.state", "plant-kiln.state".
std::string default_state_file(const Config& config);

/// Parses config text; `name` is used in error positions.
Config parse_config(const std::string& text, const std::string& name);

/// The loader quotes what a user wrote as every module does (plcemu/image/excerpt.hpp).
using image::excerpt;

}  // namespace plcemu::config
