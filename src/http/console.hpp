#pragma once
// The console's pages and static files, compiled into the binary from src/http/assets/.

#include <string_view>

#include "http/message.hpp"

namespace plcemu::http {

/// One file of src/http/assets/.
struct Asset {
    std::string_view name;          ///< "console.js"
    std::string_view content_type;  ///< "text/javascript; charset=utf-8"
    std::string_view body;
};

/// The asset named `name`, or null.
const Asset* find_asset(std::string_view name);

/// An asset as a response, with the console's content security policy (no inline script, no
/// other origin).
Response asset_response(const Asset& asset);

}  // namespace plcemu::http
