#include "plots/html_text.hpp"

#include <cmath>
#include <cstdio>

namespace viscera::player {

std::string htmlText(const std::string& s) {
    std::string o;
    for (char ch : s) {
        switch (ch) {
        case '&':
            o += "&amp;";
            break;
        case '<':
            o += "&lt;";
            break;
        case '>':
            o += "&gt;";
            break;
        case '"':
            o += "&quot;";
            break;
        default:
            o += ch;
        }
    }
    return o;
}

std::string formatNumber(const char* format, double v) {
    if (!std::isfinite(v)) { // "—" in the conversion's place, never "nan"
        std::string out = format;
        const size_t a = out.find('%');
        const size_t b = a == std::string::npos ? a : out.find_first_of("fge", a);
        if (b != std::string::npos) out.replace(a, b - a + 1, "—");
        return out;
    }
    char buf[96];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

} // namespace viscera::player
