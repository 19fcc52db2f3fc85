#include "sim/skeleton/node_weights_io.hpp"

#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "sim/util/format.hpp"
#include "sim/util/line_reader.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace viscera::sim {
std::vector<double> parseNodeWeights(std::string_view text, const std::string& origin,
                                     std::optional<size_t> expectedNodes) {
    detail::LineReader in(text, origin);
    std::vector<double> w;
    detail::readNodeValues(in, "vweights", expectedNodes, "weight",
                           [&](std::string_view tok, size_t, const std::string& what) {
                               const double x = in.number<double>(tok, what);
                               if (!(std::isfinite(x) && x > 0))
                                   in.fail(what + " is " + std::string(tok) + " (must be finite and > 0)");
                               w.push_back(x);
                           });
    return w;
}

std::string formatNodeWeights(const std::vector<double>& weights) {
    if (weights.empty()) throw std::invalid_argument("sim::formatNodeWeights(): no weights (need at least one node)");
    std::string out = "vweights 1\nnodes " + std::to_string(weights.size()) + "\n";
    out.reserve(out.size() + weights.size() * 24);
    for (size_t i = 0; i < weights.size(); ++i) {
        const double x = weights[i];
        if (!(std::isfinite(x) && x > 0))
            throw std::invalid_argument("sim::formatNodeWeights(): weight of node " + std::to_string(i) + " is " +
                                        formatNumber(x, 17) + " (must be finite and > 0)");
        out += formatNumber(x, 17);
        out += '\n';
    }
    return out;
}

std::vector<double> readNodeWeights(const std::filesystem::path& path, std::optional<size_t> expectedNodes) {
    return parseNodeWeights(readFile(path), path.filename().string(), expectedNodes);
}

void writeNodeWeights(const std::filesystem::path& path, const std::vector<double>& weights) {
    writeFileAtomic(path, formatNodeWeights(weights));
}

} // namespace viscera::sim
