#pragma once
// The import files of three HMI/SCADA tools, written from the tag export's rows
// (docs/configuration.md, "Tag export"): Kepware KEPServerEX's tag CSV, Ignition 8's tag JSON
// and Weintek EasyBuilder Pro's address tag library CSV. Each tool imports the tags of a Modbus
// device it talks to, so these files hold the PLCs' own rows; the simulator unit's registers stay
// in the csv and json exports.

#include <ostream>
#include <string>
#include <vector>

#include "export_tags.hpp"

namespace plcemu::daemon {

/// The device (Kepware device, Ignition device connection, Weintek device) a row belongs to:
/// `plcemu` for a file holding one PLC, else the row's plc with every character other than a
/// letter, a digit, `_` or `-` made `_` ("kiln", "plcs_2_").
std::string hmi_device(const TagRow& row);

/// The rows an HMI tool imports: those of a PLC's devices, not the simulator unit's.
std::vector<const TagRow*> hmi_rows(const std::vector<TagRow>& rows);

/// The digit of a table in Modbus numbers: 0 coil, 1 discrete input, 3 input register,
/// 4 holding register.
char modbus_digit(modbus::Table table);

/// The Modbus number the three tools write: the table's digit (0 coil, 1 discrete input,
/// 3 input register, 4 holding register) and the 1-based address in five digits ("400101").
std::string modbus_number(const TagRow& row);

/// Kepware KEPServerEX tag CSV for its Modbus TCP/IP Ethernet driver.
void write_kepware(std::ostream& out, const std::vector<TagRow>& rows);

/// Ignition 8 tag JSON: OPC tags on the Ignition OPC UA Server's Modbus TCP driver.
void write_ignition(std::ostream& out, const std::vector<TagRow>& rows);

/// Weintek EasyBuilder Pro address tag library CSV (user-defined tags, MODBUS TCP/IP device).
void write_weintek(std::ostream& out, const std::vector<TagRow>& rows);

}  // namespace plcemu::daemon
