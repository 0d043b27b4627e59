#include "http/console.hpp"

#include <span>

namespace plcemu::http {

// Written by cmake/EmbedAssets.cmake from src/http/assets/.
extern const Asset kAssets[];
extern const std::size_t kAssetCount;

const Asset* find_asset(std::string_view name) {
    for (const Asset& a : std::span(kAssets, kAssetCount)) {
        if (a.name == name) return &a;
    }
    return nullptr;
}

Response asset_response(const Asset& a) {
    Response r;
    r.content_type = std::string(a.content_type);
    r.body = std::string(a.body);
    // Names and values are shown as text; a page runs only the console's own files.
    r.headers.emplace_back("Content-Security-Policy",
                           "default-src 'self'; script-src 'self'; style-src 'self'; "
                           "img-src 'self' data:; connect-src 'self'; frame-ancestors 'none'; "
                           "base-uri 'none'; form-action 'none'");
    r.headers.emplace_back("Referrer-Policy", "no-referrer");
    return r;
}

}  // namespace plcemu::http
