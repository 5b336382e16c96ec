// poisson_cpu.cpp — set-up and the elementary operators of the screened Poisson problem
// (A = Pᵀ W P, b = Pᵀ W t, residual, smoothers). See poisson_cpu.h for the maths.
#include "poisson/poisson_cpu.h"

#include <cmath>
#include <string>

#include "util/error.h"

namespace gdpt {
namespace {

void checkField(const std::vector<double>& v, std::size_t n, const char* name, bool optional,
                bool nonNegative) {
    if (optional && v.empty()) return;
    if (v.size() != n)
        throw Error(std::string("Poisson problem: ") + name + " has " + std::to_string(v.size()) +
                    " values, expected " + std::to_string(n));
    for (double value : v)
        if (!std::isfinite(value) || (nonNegative && value < 0.0))
            throw Error(std::string("Poisson problem: ") + name + " has an invalid value " +
                        std::to_string(value));
}

double weightAt(const std::vector<double>& w, std::size_t i) {
    return w.empty() ? 1.0 : w[i];
}

}  // namespace

void validateProblem(const PoissonProblem& p) {
    if (p.width <= 0 || p.height <= 0)
        throw Error("Poisson problem: invalid size " + std::to_string(p.width) + "x" +
                    std::to_string(p.height));
    if (!std::isfinite(p.alpha) || p.alpha < 0.0)
        throw Error("Poisson problem: alpha must be finite and >= 0, got " + std::to_string(p.alpha));
    const std::size_t n = p.size();
    checkField(p.primal, n, "primal", false, false);
    checkField(p.dx, n, "dx", false, false);
    checkField(p.dy, n, "dy", false, false);
    checkField(p.weightPrimal, n, "weightPrimal", true, true);
    checkField(p.weightDx, n, "weightDx", true, true);
    checkField(p.weightDy, n, "weightDy", true, true);
}

PoissonOperator makeOperator(const PoissonProblem& p) {
    validateProblem(p);
    PoissonOperator op;
    op.width = p.width;
    op.height = p.height;
    const std::size_t n = p.size();
    op.cx.assign(n, 0.0);
    op.cy.assign(n, 0.0);
    op.cp.assign(n, 0.0);
    const double alpha2 = p.alpha * p.alpha;
    for (int y = 0; y < p.height; ++y)
        for (int x = 0; x < p.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * p.width + x;
            // Dropped rows (last column for dx, last row for dy) get weight 0.
            if (x + 1 < p.width) op.cx[i] = weightAt(p.weightDx, i);
            if (y + 1 < p.height) op.cy[i] = weightAt(p.weightDy, i);
            op.cp[i] = alpha2 * weightAt(p.weightPrimal, i);
        }
    return op;
}

Field computeRhs(const PoissonProblem& p) {
    validateProblem(p);
    const std::size_t w = static_cast<std::size_t>(p.width);
    Field b(p.size(), 0.0);
    const double alpha2 = p.alpha * p.alpha;
    for (int y = 0; y < p.height; ++y)
        for (int x = 0; x < p.width; ++x) {
            const std::size_t i = y * w + x;
            b[i] += alpha2 * weightAt(p.weightPrimal, i) * p.primal[i];
            // Row dx_i = I_{i+1} − I_i: Pᵀ puts −1 at pixel i and +1 at pixel i+1.
            if (x + 1 < p.width) {
                const double g = weightAt(p.weightDx, i) * p.dx[i];
                b[i] -= g;
                b[i + 1] += g;
            }
            if (y + 1 < p.height) {
                const double g = weightAt(p.weightDy, i) * p.dy[i];
                b[i] -= g;
                b[i + w] += g;
            }
        }
    return b;
}

void applyA(const PoissonOperator& op, const Field& x, Field& y) {
    const std::size_t w = static_cast<std::size_t>(op.width);
    y.assign(op.size(), 0.0);
    for (int py = 0; py < op.height; ++py)
        for (int px = 0; px < op.width; ++px) {
            const std::size_t i = py * w + px;
            double v = op.cp[i] * x[i];
            // Edges to the right/below are stored at i, edges to the left/above at the
            // neighbour; the flux c (x_i − x_j) enters row i with + and row j with −.
            if (px + 1 < op.width) v += op.cx[i] * (x[i] - x[i + 1]);
            if (px > 0) v += op.cx[i - 1] * (x[i] - x[i - 1]);
            if (py + 1 < op.height) v += op.cy[i] * (x[i] - x[i + w]);
            if (py > 0) v += op.cy[i - w] * (x[i] - x[i - w]);
            y[i] = v;
        }
}

void residual(const PoissonOperator& op, const Field& b, const Field& x, Field& r) {
    applyA(op, x, r);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = b[i] - r[i];
}

Field diagonal(const PoissonOperator& op) {
    const std::size_t w = static_cast<std::size_t>(op.width);
    Field d(op.size(), 0.0);
    for (int py = 0; py < op.height; ++py)
        for (int px = 0; px < op.width; ++px) {
            const std::size_t i = py * w + px;
            double v = op.cp[i] + op.cx[i] + op.cy[i];  // cx/cy are 0 on dropped edges
            if (px > 0) v += op.cx[i - 1];
            if (py > 0) v += op.cy[i - w];
            d[i] = v;
        }
    return d;
}

double dot(const Field& a, const Field& b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}

double norm2(const Field& a) {
    return std::sqrt(dot(a, a));
}

void jacobiSweep(const PoissonOperator& op, const Field& b, Field& x, double omega) {
    Field r;
    residual(op, b, x, r);
    const Field d = diagonal(op);
    for (std::size_t i = 0; i < x.size(); ++i)
        if (d[i] > 0.0) x[i] += omega * r[i] / d[i];
}

void gaussSeidelRedBlackSweep(const PoissonOperator& op, const Field& b, Field& x, bool redFirst) {
    const std::size_t w = static_cast<std::size_t>(op.width);
    for (int pass = 0; pass < 2; ++pass) {
        // Colour (x+y) mod 2: 0 = red, 1 = black. Pixels of one colour only couple to the
        // other colour, so each half-sweep is an exact block update (and parallel on a GPU).
        const int colour = (pass == 0) == redFirst ? 0 : 1;
        for (int py = 0; py < op.height; ++py)
            for (int px = (py + colour) % 2; px < op.width; px += 2) {
                const std::size_t i = py * w + px;
                double diag = op.cp[i];
                double sum = b[i];
                if (px + 1 < op.width) {
                    diag += op.cx[i];
                    sum += op.cx[i] * x[i + 1];
                }
                if (px > 0) {
                    diag += op.cx[i - 1];
                    sum += op.cx[i - 1] * x[i - 1];
                }
                if (py + 1 < op.height) {
                    diag += op.cy[i];
                    sum += op.cy[i] * x[i + w];
                }
                if (py > 0) {
                    diag += op.cy[i - w];
                    sum += op.cy[i - w] * x[i - w];
                }
                if (diag > 0.0) x[i] = sum / diag;
            }
    }
}

}  // namespace gdpt
