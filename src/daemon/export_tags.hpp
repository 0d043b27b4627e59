#pragma once
// `plcemud --export-tags csv|json|kepware|ignition|weintek`: one row per device the
// configuration gives meaning to, with the Modbus unit, table and address that serve it, for an
// HMI/SCADA tag import (docs/configuration.md, "Tag export").

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "plcemu/config/config.hpp"
#include "plcemu/modbus/unit.hpp"

namespace plcemu::daemon {

/// One exported tag.
struct TagRow {
    /// The `plcs:` entry it belongs to ("kiln", "plcs[2]", config::plc_id); empty for a file
    /// holding one PLC, whose export has no `plc` and `endpoint` columns.
    std::string plc;
    /// Where a `plcs:` entry's rows are reached: "tcp:BIND:PORT", "rtu:DEVICE", or both
    /// separated by a space.
    std::string endpoint;
    /// Unique in the export: the device ("R100"), or "sim.ch0.ambient"; a `plcs:` entry's tags
    /// are prefixed with its plc ("kiln.R100").
    std::string name;
    std::string device;  ///< the PLC's device, as the profile writes it; empty for the simulator
    int unit = 0;        ///< the Modbus unit ID that serves it
    modbus::Table table = modbus::Table::HoldingRegisters;  ///< the table
    std::uint16_t address = 0;                              ///< wire address (0-based)
    std::string type;         ///< bool, int16, uint16, int32 (two registers, low word first)
    bool writable = false;    ///< a Modbus write reaches it
    std::string description;  ///< what the configuration makes of it
    /// How a FATEK master names it ("R00100", "DRC0200"), for a family that speaks FATEK's
    /// protocol; empty otherwise (the column is left out when no row has one).
    std::string fatek;
};

/// The rows of a config, and what it describes that no Modbus address serves.
struct TagExport {
    std::vector<TagRow> rows;              ///< by unit, table and address
    std::vector<std::string> unreachable;  ///< "R4170: …", devices without an address
};

/// Builds the config's PLC (presets applied, program bound) and lists what its program, its
/// profile and its simulator unit give meaning to. Throws config::ConfigError.
TagExport export_tags(const config::Config& config);

/// The table as the export writes it: coil, discrete_input, holding_register, input_register.
const char* table_key(modbus::Table table);

/// The tags of every PLC of a config, in `plcs:` order; a file holding one PLC gives exactly
/// export_tags(config). Rows and unreachable devices of an entry are named with its plc_id as
/// a prefix ("kiln.R100").
TagExport export_tags(const std::vector<config::Config>& plcs);

/// "tcp:127.0.0.1:1502", "tcp:[::]:502 rtu:/dev/ttyUSB0": the listeners a PLC's config opens.
std::string endpoint_of(const config::Config& config);

/// Writes `rows` as CSV (a header, then one line a row) or as a JSON array of objects with the
/// same keys; rows of `plcs:` entries add the `plc` and `endpoint` keys.
void write_tags(std::ostream& out, const std::vector<TagRow>& rows, bool json);

/// What `--export-tags` writes: the project's own CSV or JSON, or the import file of an HMI tool
/// (docs/configuration.md, "Tag export").
enum class TagFormat { Csv, Json, Kepware, Ignition, Weintek };

/// The format named "csv", "json", "kepware", "ignition" or "weintek"; false for another name.
bool parse_tag_format(const std::string& name, TagFormat& format);

/// Writes `rows` in `format`.
void write_tags(std::ostream& out, const std::vector<TagRow>& rows, TagFormat format);

/// A CSV field, quoted when it holds a comma, a quote or a line break, or `always` (RFC 4180).
std::string csv_field(const std::string& s, bool always = false);

/// A JSON string literal: quotes, backslashes and control characters escaped.
std::string json_string(const std::string& s);

}  // namespace plcemu::daemon
