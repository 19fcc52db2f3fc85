#pragma once
/// Small text helpers of the HTML pages (session plots, results) and their tables.
#include <string>

namespace viscera::player {

/// `s` with & < > " escaped for HTML text and attribute values.
std::string htmlText(const std::string& s);
/// printf of one double, e.g. formatNumber("%.1f s", 12.34) == "12.3 s"; a non-finite value
/// prints as "—" in the conversion's place (never "nan").
std::string formatNumber(const char* format, double v);
/// The shared style sheet of the results pages.
inline constexpr const char* kPageStyle =
    "body{font-family:sans-serif;max-width:1000px;margin:24px auto;color:#282830}table{border-collapse:"
    "collapse;margin:12px 0}td,th{padding:3px 14px 3px 0;text-align:left}th{color:#666;font-weight:normal}"
    ".ok{color:#1a7a2a}.bad{color:#b00}figure{margin:18px 0}img{max-width:100%;border:1px solid #ddd}"
    ".foot{color:#888}";

} // namespace viscera::player
