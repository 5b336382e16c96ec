// spacetime_pcg.cpp — conjugate gradients on the space-time normal equations (spacetime_pcg.h).
#include "poisson/spacetime_pcg.h"

#include <cmath>
#include <vector>

#include "util/parallel.h"

namespace gdpt::spacetime {

std::array<ChannelSolve, 3> pcg(const Operator& op, const std::array<Field, 3>& b, std::array<Field, 3>& x,
                                double tolerance, int maxIterations, std::uint32_t threads, CgVectors& v,
                                const std::function<void(int)>& every16,
                                std::optional<std::chrono::steady_clock::time_point> deadline,
                                FrameBlocks* mg, bool coupleFrames) {
    const std::size_t n = op.size(), ranges = rangesOf(n);
    const Field& jd = op.jacobiDiag();
    std::array<Field, 3>&r = v.r, &p = v.p, &q = v.q;
    // Per range: the partial sums of one pass (three per channel at most), added in range order.
    std::vector<std::array<double, 9>> partial(ranges);
    const auto sumOf = [&](int slot) {
        double s = 0.0;
        for (const auto& part : partial) s += part[std::size_t(slot)];
        return s;
    };
    for (int c = 0; c < 3; ++c) {
        sized(r[c], n);
        sized(p[c], n);
        sized(q[c], n);
        if (mg) sized(v.z[c], n);
    }
    // z = M⁻¹ r and r·z for the channels in `which` (multigrid).
    const auto precondition = [&](const std::array<bool, 3>& which) {
        mg->apply(op, r, v.z, which, threads, coupleFrames);
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            std::array<double, 9> s{};
            for (int c = 0; c < 3; ++c) {
                if (!which[c]) continue;
                double rz = 0.0;
                for (std::size_t i = begin; i < end; ++i) rz += r[c][i] * v.z[c][i];
                s[std::size_t(c)] = rz;
            }
            partial[begin / kGrain] = s;
        });
    };
    const bool mixed = !op.cmx.empty();
    const auto rowsOf = [&](int c, bool y) -> const Field* {
        return mixed ? &(y ? v.rows.y : v.rows.x)[std::size_t(c)] : nullptr;
    };
    // r = b − A x, ‖b‖² and ‖r‖²; Jacobi: p = z = r / d and r·z (multigrid: below).
    if (mixed) mixedRowValues(op, x, {true, true, true}, v.rows, threads);
    parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
        std::array<double, 9> s{};
        for (int c = 0; c < 3; ++c) {
            applyRange(op, x[c], q[c], begin, end, rowsOf(c, false), rowsOf(c, true));
            double bb = 0.0, rz = 0.0, rr = 0.0;
            for (std::size_t i = begin; i < end; ++i) {
                const double ri = b[c][i] - q[c][i];
                r[c][i] = ri;
                if (!mg) {
                    p[c][i] = ri / jd[i];
                    rz += ri * p[c][i];
                }
                bb += b[c][i] * b[c][i];
                rr += ri * ri;
            }
            s[std::size_t(c)] = bb;
            s[std::size_t(c) + 3] = rz;
            s[std::size_t(c) + 6] = rr;
        }
        partial[begin / kGrain] = s;
    });
    std::array<ChannelSolve, 3> out;
    std::array<double, 3> rz{}, rr{}, target{}, alpha{}, beta{};
    std::array<bool, 3> active{};
    for (int c = 0; c < 3; ++c) {
        out[c].rhsNorm = std::sqrt(sumOf(c));
        rz[c] = sumOf(c + 3);
        rr[c] = sumOf(c + 6);
        target[c] = tolerance * out[c].rhsNorm;
        active[c] = std::sqrt(rr[c]) > target[c] && maxIterations > 0;
    }
    if (mg && (active[0] || active[1] || active[2])) {
        precondition(active);
        for (int c = 0; c < 3; ++c)
            if (active[c]) {
                rz[c] = sumOf(c);
                std::copy(v.z[c].begin(), v.z[c].end(), p[c].begin());
            }
    }
    const auto anyActive = [&] { return active[0] || active[1] || active[2]; };
    int k = 0;
    bool cut = false;
    while (anyActive()) {
        if (every16 && k > 0 && k % 16 == 0) every16(k);
        if (deadline && std::chrono::steady_clock::now() >= *deadline) {
            cut = true;  // the iterate so far: every CG iterate is an image of lower energy
            break;
        }
        ++k;
        // q = A p and p·q.
        if (mixed) mixedRowValues(op, p, active, v.rows, threads);
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            std::array<double, 9> s{};
            for (int c = 0; c < 3; ++c) {
                if (!active[c]) continue;
                applyRange(op, p[c], q[c], begin, end, rowsOf(c, false), rowsOf(c, true));
                double pq = 0.0;
                for (std::size_t i = begin; i < end; ++i) pq += p[c][i] * q[c][i];
                s[std::size_t(c)] = pq;
            }
            partial[begin / kGrain] = s;
        });
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            const double pq = sumOf(c);
            if (!(pq > 0.0)) {
                active[c] = false;  // breakdown: keep x
                continue;
            }
            alpha[c] = rz[c] / pq;
        }
        // x += α p, r −= α q, and r·z, r·r.
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            std::array<double, 9> s{};
            for (int c = 0; c < 3; ++c) {
                if (!active[c]) continue;
                double rzNew = 0.0, rrNew = 0.0;
                const double a = alpha[c];
                for (std::size_t i = begin; i < end; ++i) {
                    x[c][i] += a * p[c][i];
                    const double ri = r[c][i] - a * q[c][i];
                    r[c][i] = ri;
                    if (!mg) rzNew += ri * ri / jd[i];  // multigrid: r·z after the cycle
                    rrNew += ri * ri;
                }
                s[std::size_t(c)] = rzNew;
                s[std::size_t(c) + 3] = rrNew;
            }
            partial[begin / kGrain] = s;
        });
        std::array<double, 3> rzNew{};
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            rzNew[c] = sumOf(c);
            rr[c] = sumOf(c + 3);
            ++out[c].iterations;
            active[c] = std::sqrt(rr[c]) > target[c] && out[c].iterations < maxIterations;
        }
        if (!anyActive()) break;
        if (mg) {
            precondition(active);
            for (int c = 0; c < 3; ++c)
                if (active[c]) rzNew[c] = sumOf(c);
        }
        for (int c = 0; c < 3; ++c) {
            if (!active[c]) continue;
            beta[c] = rzNew[c] / rz[c];
            rz[c] = rzNew[c];
        }
        // p = r / d + β p.
        parallelRanges(threads, n, kGrain, [&](std::size_t begin, std::size_t end) {
            for (int c = 0; c < 3; ++c) {
                if (!active[c]) continue;
                const double bt = beta[c];
                if (mg)
                    for (std::size_t i = begin; i < end; ++i) p[c][i] = v.z[c][i] + bt * p[c][i];
                else
                    for (std::size_t i = begin; i < end; ++i) p[c][i] = r[c][i] / jd[i] + bt * p[c][i];
            }
        });
    }
    for (int c = 0; c < 3; ++c) {
        out[c].residualNorm = std::sqrt(rr[c]);
        out[c].converged = out[c].residualNorm <= target[c];
        out[c].stoppedAtDeadline = cut;
    }
    return out;
}

}  // namespace gdpt::spacetime
