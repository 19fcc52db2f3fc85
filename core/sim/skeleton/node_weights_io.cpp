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
namespace {

constexpr int64_t kMaxNodes = int64_t{1} << 28;

using Lines = detail::LineReader;

} // namespace

std::vector<double> parseNodeWeights(std::string_view text, const std::string& origin,
                                     std::optional<size_t> expectedNodes) {
    Lines in(text, origin);
    std::vector<std::string_view> tok;
    if (!in.next(tok)) in.failEof("header 'vweights 1'");
    if (tok.size() != 2 || tok[0] != "vweights") in.fail("header must be 'vweights <version>'");
    if (in.number<int>(tok[1], "version") != 1)
        in.fail("unsupported vweights version " + std::string(tok[1]) + " (supported: 1)");
    if (!in.next(tok)) in.failEof("'nodes <count>'");
    if (tok.size() != 2 || tok[0] != "nodes") in.fail("expected 'nodes <count>'");
    const int64_t n = in.number<int64_t>(tok[1], "node count");
    if (n < 1 || n > kMaxNodes) in.fail("node count " + std::to_string(n) + " is out of range [1, 2^28]");
    if (expectedNodes && static_cast<size_t>(n) != *expectedNodes)
        in.fail("file has " + std::to_string(n) + " nodes, the mesh has " + std::to_string(*expectedNodes));
    std::vector<double> w;
    w.reserve(static_cast<size_t>(n));
    for (int64_t i = 0; i < n; ++i) {
        const std::string what = "weight of node " + std::to_string(i);
        if (!in.next(tok)) in.failEof(what + " (file declares " + std::to_string(n) + " nodes)");
        if (tok.size() != 1) in.fail(what + ": expected one value per line, found " + std::to_string(tok.size()));
        const double x = in.number<double>(tok[0], what);
        if (!(std::isfinite(x) && x > 0)) in.fail(what + " is " + std::string(tok[0]) + " (must be finite and > 0)");
        w.push_back(x);
    }
    if (in.next(tok))
        in.fail("unexpected content after the last weight (file declares " + std::to_string(n) + " nodes)");
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
