#include "integrator/mlt_estimate.h"

#include <algorithm>
#include <cmath>

#include "lib/mlt.glsl"
#include "lib/rng.glsl"
#include "util/error.h"

namespace gdpt {

void TargetSums::add(float target) {
    const double v = std::isfinite(target) && target > 0.0f ? double(target) : 0.0;
    sum += v;
    sumSquares += v * v;
    ++count;
}

void TargetSums::add(const TargetSums& other) {
    sum += other.sum;
    sumSquares += other.sumSquares;
    count += other.count;
}

MltNormalisation TargetSums::normalisation() const {
    MltNormalisation n;
    n.samples = count;
    if (count == 0) return n;
    const double c = double(count);
    n.b = sum / c;
    if (count > 1) n.standardError = std::sqrt(std::max(0.0, (sumSquares - sum * n.b) / (c - 1.0)) / c);
    return n;
}

double TargetSums::effectiveSampleSize() const {
    return sumSquares > 0.0 ? sum * sum / sumSquares : 0.0;
}

MltNormalisation mltNormalisation(const std::vector<float>& targets) {
    TargetSums s;
    for (float t : targets) s.add(t);
    return s.normalisation();
}

std::vector<std::uint32_t> mltChainStarts(const std::vector<float>& targets, std::uint32_t chains,
                                          std::uint32_t seed) {
    double total = 0.0;
    for (float t : targets) total += std::isfinite(t) && t > 0.0f ? double(t) : 0.0;
    std::vector<std::uint32_t> starts;
    if (!(total > 0.0) || chains == 0) return starts;
    starts.reserve(chains);
    // Systematic resampling: chain c takes the sample whose cumulative interval holds
    // (c + u) · total / chains.
    const double u = double(gpu::pcgHash(seed ^ 0x5354u) >> 8) / 16777216.0;
    const double step = total / double(chains);
    double cumulative = 0.0;
    std::size_t i = 0;
    for (std::uint32_t c = 0; c < chains; ++c) {
        const double at = (double(c) + u) * step;
        while (i + 1 < targets.size()) {
            const double t = std::isfinite(targets[i]) && targets[i] > 0.0f ? double(targets[i]) : 0.0;
            if (cumulative + t > at) break;
            cumulative += t;
            ++i;
        }
        // Rounding may leave `at` past the last positive sample: step back to it.
        std::size_t j = i;
        while (j > 0 && !(std::isfinite(targets[j]) && targets[j] > 0.0f)) --j;
        starts.push_back(static_cast<std::uint32_t>(j));
    }
    return starts;
}

float MltBlockNormaliser::divisor(std::uint32_t pixel, std::uint32_t width) const {
    if (block == 0) return 1.0f;
    return divisors[gpu::mltBlockIndex(pixel % width, pixel / width, block, columns)];
}

MltBlockNormaliser mltBlockNormaliser(const std::vector<gpu::MltBootstrapSample>& samples,
                                      std::uint32_t width, std::uint32_t height, std::uint32_t block,
                                      float exponent) {
    MltBlockNormaliser n;
    if (block == 0) return n;
    GDPT_CHECK(width > 0 && height > 0 && exponent > 0.0f);
    n.block = block;
    n.columns = (width + block - 1) / block;
    n.rows = (height + block - 1) / block;
    const std::size_t blocks = std::size_t(n.columns) * n.rows;
    std::vector<double> sum(blocks, 0.0), count(blocks, 0.0);
    double total = 0.0, samplesUsed = 0.0;
    for (std::size_t i = 0; i < samples.size(); i += 2) {
        const gpu::MltBootstrapSample& s = samples[i];
        if (std::uint64_t{s.pixel} >= std::uint64_t{width} * height) continue;
        // T from T^γ: the block means are of the untempered target.
        const double t =
            std::isfinite(s.target) && s.target > 0.0f
                ? (exponent == 1.0f ? double(s.target) : std::pow(double(s.target), 1.0 / exponent))
                : 0.0;
        const std::uint32_t k = gpu::mltBlockIndex(s.pixel % width, s.pixel / width, block, n.columns);
        sum[k] += t;
        count[k] += 1.0;
        total += t;
        samplesUsed += 1.0;
    }
    n.divisors.assign(blocks, 1.0f);
    if (!(total > 0.0)) return n;
    const double floor = kMltBlockFloor * total / samplesUsed;
    for (std::size_t k = 0; k < blocks; ++k) {
        const double mean = count[k] > 0.0 ? sum[k] / count[k] : 0.0;
        n.divisors[k] = static_cast<float>(std::pow(mean + floor, double(exponent)));
    }
    return n;
}

MltAccumulator::MltAccumulator(int width, int height, float misNormalisation, float largeStep)
    : width_(width),
      height_(height),
      misNormalisation_(misNormalisation),
      largeStep_(largeStep),
      sums_(std::size_t(width) * std::size_t(height) * gpu::kMltValues * 3, 0.0),
      largeSums_(sums_.size(), 0.0) {}

void MltAccumulator::add(const gpu::MltRecord* records, std::size_t count) {
    const std::size_t pixels = std::size_t(width_) * std::size_t(height_);
    for (std::size_t r = 0; r < count; ++r) {
        const gpu::MltRecord& rec = records[r];
        const bool large = rec.largeTarget >= 0.0f;
        if (large) largeSteps_.add(rec.largeTarget);
        if (rec.pixel >= pixels) continue;
        const std::size_t at = std::size_t(rec.pixel) * gpu::kMltValues * 3;
        const auto splat = [&](std::vector<double>& sums, double w) {
            for (std::uint32_t k = 0; k < gpu::kMltValues; ++k)
                for (std::uint32_t c = 0; c < 3; ++c) sums[at + k * 3 + c] += w * double(rec.value[k][c]);
        };
        if (rec.weight > 0.0f) splat(sums_, rec.weight);
        if (large && rec.largeTarget > 0.0f)
            splat(largeSums_, gpu::mltLargeStepWeight(rec.largeTarget, misNormalisation_, largeStep_));
    }
}

Image MltAccumulator::quantity(std::uint32_t k, MltScale scale) const {
    Image out(width_, height_);
    const std::size_t pixels = std::size_t(width_) * std::size_t(height_);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) {
            const std::size_t at = (p * gpu::kMltValues + k) * 3 + std::size_t(c);
            out.plane(c)[p] = static_cast<float>(scale.metropolis * sums_[at] + scale.large * largeSums_[at]);
        }
    return out;
}

MltImages resolveGradientSamples(const MltAccumulator& acc, MltScale scale) {
    const Image central = acc.quantity(gpu::kMltCentral, scale);
    Image neighbor[4], gradient[4];
    for (std::uint32_t i = 0; i < 4; ++i) {
        neighbor[i] = acc.quantity(gpu::kMltNeighbor + i, scale);
        gradient[i] = acc.quantity(gpu::kMltGradient + i, scale);
    }
    const int w = central.width(), h = central.height();
    MltImages out{Image(w, h), Image(w, h), Image(w, h)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(w) + std::size_t(x);
            for (int c = 0; c < 3; ++c) {
                // Neighbour q = p − δ_i sent its offset i to p (right, down, left, up).
                double sum = central.plane(c)[p];
                double k = 0.0;
                if (x > 0) sum += neighbor[gpu::kGptRight].plane(c)[p - 1], k += 1.0;
                if (y > 0) sum += neighbor[gpu::kGptDown].plane(c)[p - std::size_t(w)], k += 1.0;
                if (x + 1 < w) sum += neighbor[gpu::kGptLeft].plane(c)[p + 1], k += 1.0;
                if (y + 1 < h) sum += neighbor[gpu::kGptUp].plane(c)[p + std::size_t(w)], k += 1.0;
                out.primal.plane(c)[p] = static_cast<float>(sum / std::max(k, 1.0));
                if (x + 1 < w)
                    out.dx.plane(c)[p] =
                        gradient[gpu::kGptRight].plane(c)[p] - gradient[gpu::kGptLeft].plane(c)[p + 1];
                if (y + 1 < h)
                    out.dy.plane(c)[p] = gradient[gpu::kGptDown].plane(c)[p] -
                                         gradient[gpu::kGptUp].plane(c)[p + std::size_t(w)];
            }
        }
    return out;
}

}  // namespace gdpt
