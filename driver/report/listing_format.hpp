#pragma once
// The one --format every listing command takes (query curve, validation, work-precision, cases;
// study status): an aligned table for people, CSV and JSON for scripts.
#include <array>
#include <string>

namespace boycott::driver {

enum class ListingFormat { kTable, kCsv, kJson };
/// The names, in the order help lists them.
inline constexpr std::array<const char*, 3> kListingFormatNames = {"table", "csv", "json"};
/// InputError naming the value and the choices for any other name.
ListingFormat parse_listing_format(const std::string& s);

}  // namespace boycott::driver
