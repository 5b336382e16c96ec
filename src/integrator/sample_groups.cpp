// sample_groups.cpp — groups of samples and the variance of paired differences (sample_groups.h).
#include "integrator/sample_groups.h"

#include <algorithm>
#include <string>
#include <utility>

#include "poisson/poisson_spacetime.h"
#include "util/error.h"

namespace gdpt {

SampleGroupRecorder SampleGroupRecorder::everyBatch(std::size_t maxGroups) {
    if (maxGroups < 2) throw Error("sample groups: at least 2 groups must be kept");
    SampleGroupRecorder r;
    r.maxGroups_ = maxGroups;
    return r;
}

SampleGroupRecorder SampleGroupRecorder::atEnds(std::vector<std::uint32_t> ends) {
    if (!std::is_sorted(ends.begin(), ends.end()) ||
        std::adjacent_find(ends.begin(), ends.end()) != ends.end() || (!ends.empty() && ends.front() == 0))
        throw Error("sample groups: the ends must be positive and increasing");
    SampleGroupRecorder r;
    r.wanted_ = std::move(ends);
    return r;
}

bool SampleGroupRecorder::wants(std::uint32_t done) const {
    if (maxGroups_ > 0) return true;
    return std::binary_search(wanted_.begin(), wanted_.end(), done);
}

void SampleGroupRecorder::record(std::uint32_t done, std::vector<Image> means) {
    if (!wants(done)) return;
    if (!groups_.ends.empty() && done <= groups_.ends.back())
        throw Error("sample groups: a group ends at " + std::to_string(done) +
                    " samples, not after the last (" + std::to_string(groups_.ends.back()) + ")");
    groups_.ends.push_back(done);
    groups_.means.push_back(std::move(means));
    if (maxGroups_ == 0 || groups_.ends.size() <= maxGroups_) return;
    // Keep the last end and every other one counted back from it.
    SampleGroups kept;
    const std::size_t k = groups_.ends.size();
    for (std::size_t i = 0; i < k; ++i)
        if ((k - 1 - i) % 2 == 0) {
            kept.ends.push_back(groups_.ends[i]);
            kept.means.push_back(std::move(groups_.means[i]));
        }
    groups_ = std::move(kept);
}

std::vector<std::uint32_t> equalGroupEnds(std::uint32_t n, std::size_t groups) {
    const std::uint64_t g = std::min<std::uint64_t>(groups, n);
    std::vector<std::uint32_t> ends;
    for (std::uint64_t k = 1; k <= g; ++k) ends.push_back(std::uint32_t((k * n + g - 1) / g));
    return ends;
}

Image pairedDifferenceVariance(const SampleGroups& later, const SampleGroups& earlier, std::size_t layer,
                               const std::vector<std::uint32_t>& partner) {
    if (later.ends != earlier.ends)
        throw Error("paired differences: the two renders' sample groups differ (" +
                    std::to_string(later.ends.size()) + " and " + std::to_string(earlier.ends.size()) +
                    " groups)");
    const std::size_t groups = earlier.ends.size();
    if (groups < 2) return {};
    for (const SampleGroups* g : {&later, &earlier})
        for (const std::vector<Image>& m : g->means)
            if (layer >= m.size() || m[layer].width() != earlier.means[0][layer].width() ||
                m[layer].height() != earlier.means[0][layer].height())
                throw Error("paired differences: a group lacks the layer or has another size");
    const Image& shape = earlier.means[0][layer];
    const std::size_t pixels = shape.pixelCount();
    if (!partner.empty() && partner.size() != pixels)
        throw Error("paired differences: the partner map does not match the image");
    const double n = double(earlier.ends.back());
    Image out(shape.width(), shape.height());
    std::vector<double> d(groups), m(groups);
    for (std::size_t j = 0; j < groups; ++j)
        m[j] = double(earlier.ends[j]) - (j > 0 ? earlier.ends[j - 1] : 0.0);
    // Group j's mean from the cumulative means at its ends: (e_j M_j − e_j−1 M_j−1) / m_j.
    const auto groupMean = [&](const SampleGroups& g, std::size_t j, int c, std::size_t i) {
        const double sum = double(g.ends[j]) * g.means[j][layer].plane(c)[i] -
                           (j > 0 ? double(g.ends[j - 1]) * g.means[j - 1][layer].plane(c)[i] : 0.0);
        return sum / m[j];
    };
    for (int c = 0; c < 3; ++c)
        for (std::size_t p = 0; p < pixels; ++p) {
            const std::uint32_t q = partner.empty() ? std::uint32_t(p) : partner[p];
            if (q == kNoTemporalPartner) continue;
            double mean = 0.0;
            for (std::size_t j = 0; j < groups; ++j) {
                d[j] = groupMean(later, j, c, q) - groupMean(earlier, j, c, p);
                mean += m[j] * d[j];
            }
            mean /= n;
            double ss = 0.0;
            for (std::size_t j = 0; j < groups; ++j) ss += m[j] * (d[j] - mean) * (d[j] - mean);
            out.plane(c)[p] = float(ss / double(groups - 1) / n);
        }
    return out;
}

}  // namespace gdpt
