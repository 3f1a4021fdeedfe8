#include "fss/streamline.h"

#include "fss/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>

namespace fss {
namespace {

std::string pointName(const Eigen::Vector2d& p) {
    std::ostringstream s;
    s << "(" << p.x() << ", " << p.y() << ")";
    return s.str();
}

void validate(const StreamlineOptions& o) {
    if (!(o.step > 0) || !std::isfinite(o.step))
        throw InvalidInputError("The streamline step must be positive and finite.");
    if (!(o.minStep > 0) || o.minStep > o.step)
        throw InvalidInputError("The streamline minimum step must be positive and not larger than the step.");
    if (!(o.maxLength > 0)) throw InvalidInputError("The streamline maximum length must be positive.");
    if (!std::isfinite(o.minAnisotropy) || !std::isfinite(o.maxTurnDeg) || o.maxTurnDeg <= 0)
        throw InvalidInputError("The streamline anisotropy and turn thresholds must be finite (turn > 0).");
}

// Field evaluation with the stop tests of one position.
struct Evaluation {
    std::optional<Eigen::Vector2d> direction;
    StreamlineStop reason = StreamlineStop::Background;
};

class Tracer {
public:
    Tracer(const DirectionField& field, const StreamlineOptions& options) : field_(field), o_(options) {}

    Evaluation evaluate(const Eigen::Vector2d& p, const Eigen::Vector2d& reference) const {
        Evaluation e;
        if (!(p.x() >= 0 && p.y() >= 0 && p.x() <= field_.width && p.y() <= field_.height)) {
            e.reason = StreamlineStop::ImageBorder;
            return e;
        }
        if (o_.insideRegion && !o_.insideRegion(p)) {
            e.reason = StreamlineStop::OutsideRegion;
            return e;
        }
        const bool straight = o_.lowAnisotropy == LowAnisotropyPolicy::ContinueStraight;
        const std::optional<DirectionSample> s =
            field_.sample(p, reference, straight ? o_.minAnisotropy : 0.0);
        if (!s) {
            e.reason = StreamlineStop::Background;
            return e;
        }
        if (!straight && s->anisotropy < o_.minAnisotropy) {
            e.reason = StreamlineStop::LowAnisotropy;
            return e;
        }
        e.direction = s->direction;
        return e;
    }

private:
    const DirectionField& field_;
    const StreamlineOptions& o_;
};

} // namespace

Polyline2 Streamline::forward() const {
    if (points.empty()) return {};
    return Polyline2(points.begin() + std::ptrdiff_t(seedIndex), points.end());
}

Polyline2 Streamline::backward() const {
    if (points.empty()) return {};
    Polyline2 out(points.begin(), points.begin() + std::ptrdiff_t(seedIndex) + 1);
    std::reverse(out.begin(), out.end());
    return out;
}

StreamlineHalf traceStreamlineHalf(const DirectionField& field, const Eigen::Vector2d& seed,
                                   const Eigen::Vector2d& initialDirection,
                                   const StreamlineOptions& options) {
    validate(options);
    if (!seed.allFinite() || !initialDirection.allFinite() || initialDirection.isZero())
        throw InvalidInputError("A streamline needs a finite seed and a non-zero initial direction.");
    const Tracer tracer(field, options);
    const Evaluation start = tracer.evaluate(seed, initialDirection);
    if (!start.direction)
        throw InvalidInputError("The streamline seed " + pointName(seed) +
                                " lies where the direction field is undefined (background, image border, "
                                "outside the region or too low anisotropy).");

    const double cosMaxTurn = std::cos(options.maxTurnDeg * std::numbers::pi / 180.0);
    StreamlineHalf half;
    half.points.push_back(seed);
    Eigen::Vector2d p = seed, previous = *start.direction;
    double step = options.step;
    std::size_t steps = 0;
    // The field at p aligned with `previous`: the last accepted step's end evaluation is exactly the next
    // step's first (same position, same reference), so each step costs four field samples, not five.
    std::optional<Evaluation> atP;
    for (;;) {
        if (steps >= options.maxSteps) {
            half.stop = StreamlineStop::StepLimit;
            break;
        }
        const double remaining = options.maxLength - half.length;
        if (remaining <= 0) {
            half.stop = StreamlineStop::MaxLength;
            break;
        }
        const bool last = remaining <= step;
        const double h = last ? remaining : step;

        // One RK4 step; every evaluation aligned with the previous step's direction.
        std::optional<StreamlineStop> failure;
        Eigen::Vector2d delta = Eigen::Vector2d::Zero();
        {
            if (!atP) atP = tracer.evaluate(p, previous);
            const Evaluation& k1 = *atP;
            const Evaluation k2 = k1.direction ? tracer.evaluate(p + 0.5 * h * *k1.direction, previous) : k1;
            const Evaluation k3 = k2.direction ? tracer.evaluate(p + 0.5 * h * *k2.direction, previous) : k2;
            const Evaluation k4 = k3.direction ? tracer.evaluate(p + h * *k3.direction, previous) : k3;
            if (!k4.direction) {
                failure = k4.reason;
            } else {
                delta =
                    (h / 6.0) * (*k1.direction + 2.0 * *k2.direction + 2.0 * *k3.direction + *k4.direction);
                if (!(delta.norm() > 0)) failure = StreamlineStop::SharpTurn;
            }
        }
        if (!failure && last) delta *= remaining / delta.norm(); // end exactly at maxLength
        Eigen::Vector2d q = p + delta;
        std::optional<Evaluation> atQ;
        if (!failure) {
            // Aligned with the new heading: if the step is accepted this is the next step's k1.
            atQ = tracer.evaluate(q, delta);
            if (!atQ->direction)
                failure = atQ->reason;
            else if (delta.normalized().dot(previous) < cosMaxTurn)
                failure = StreamlineStop::SharpTurn;
        }
        if (failure) {
            if (h > options.minStep) {
                step = std::max(options.minStep, 0.5 * h);
                continue;
            }
            half.stop = *failure;
            break;
        }

        // Accept the step, moved onto the attracting curve when there is one nearby.
        if (options.attractor && !last) {
            if (const std::optional<Eigen::Vector2d> a = options.attractor(q, delta.normalized());
                a && a->allFinite() && (*a - p).norm() > 1e-9) {
                const Eigen::Vector2d moved = *a - p;
                if (Evaluation e = tracer.evaluate(*a, moved); e.direction && moved.dot(previous) > 0) {
                    q = *a;
                    delta = moved;
                    atQ = std::move(e);
                }
            }
        }
        const double len = delta.norm();
        half.points.push_back(q);
        half.length += len;
        previous = delta / len;
        ++steps;
        if (last) {
            half.length = options.maxLength;
            half.stop = StreamlineStop::MaxLength;
            break;
        }
        // Closed integral curve: the step passed the seed again, heading the way it started.
        if (half.length > 8.0 * options.step) {
            const double t = std::clamp((seed - p).dot(delta) / (len * len), 0.0, 1.0);
            if ((p + t * delta - seed).norm() < 0.5 * options.step && previous.dot(*start.direction) > 0) {
                half.stop = StreamlineStop::Closed;
                break;
            }
        }
        p = q;
        atP = std::move(atQ);
        step = std::min(options.step, 2.0 * step);
    }
    return half;
}

Streamline traceStreamline(const DirectionField& field, const Eigen::Vector2d& seed,
                           const StreamlineOptions& options, const Eigen::Vector2d& preferredDirection) {
    validate(options);
    if (!seed.allFinite()) throw InvalidInputError("The streamline seed must be finite.");
    const int px = int(std::floor(seed.x())), py = int(std::floor(seed.y()));
    const int cx = std::min(px, field.width - 1), cy = std::min(py, field.height - 1);
    if (!(seed.x() >= 0 && seed.y() >= 0 && seed.x() <= field.width && seed.y() <= field.height) ||
        !field.isValid(cx, cy))
        throw InvalidInputError("The streamline seed " + pointName(seed) +
                                " lies on the background or outside the image.");
    Eigen::Vector2d reference = preferredDirection;
    if (!reference.allFinite() || reference.isZero()) reference = field.pixel(cx, cy).direction;
    const std::optional<DirectionSample> s = field.sample(seed, reference);
    if (!s)
        throw InvalidInputError("The direction field is undefined at the streamline seed " + pointName(seed) +
                                ".");

    const StreamlineHalf fwd = traceStreamlineHalf(field, seed, s->direction, options);
    StreamlineHalf bwd;
    bwd.points.push_back(seed);
    if (fwd.stop != StreamlineStop::Closed)
        bwd = traceStreamlineHalf(field, seed, -s->direction, options);
    else
        bwd.stop = StreamlineStop::Closed;

    Streamline line;
    line.points.assign(bwd.points.rbegin(), bwd.points.rend());
    line.seedIndex = bwd.points.size() - 1;
    line.points.insert(line.points.end(), fwd.points.begin() + 1, fwd.points.end());
    line.backwardStop = bwd.stop;
    line.forwardStop = fwd.stop;
    return line;
}

double polylineLength(const Polyline2& line) {
    double len = 0;
    for (std::size_t i = 1; i < line.size(); ++i)
        len += (line[i] - line[i - 1]).norm();
    return len;
}

Polyline2 resampleAtSpacing(const Polyline2& line, double h) {
    if (!(h > 0) || !std::isfinite(h))
        throw InvalidInputError("The resampling spacing h must be positive and finite.");
    Polyline2 out;
    if (line.empty()) return out;
    Eigen::Vector2d q = line.front();
    out.push_back(q);
    const double h2 = h * h;
    // Walk the segments; q is always inside the circle |x − q| ≤ h at the current segment's start, so the
    // first crossing of the circle is the larger root of |a + t·d − q|² = h² on the segment.
    for (std::size_t i = 0; i + 1 < line.size();) {
        const Eigen::Vector2d& a = line[i];
        const Eigen::Vector2d d = line[i + 1] - a;
        const double A = d.squaredNorm();
        if (!(A > 0)) {
            ++i;
            continue;
        }
        const Eigen::Vector2d e = a - q;
        const double B = d.dot(e), C = e.squaredNorm() - h2;
        const double disc = B * B - A * C;
        if (disc < 0) {
            ++i;
            continue;
        }
        const double t = (-B + std::sqrt(disc)) / A;
        if (t > 1.0) {
            ++i;
            continue;
        }
        q = a + t * d;
        out.push_back(q);
    }
    return out;
}

Streamline resampleAtSpacing(const Streamline& line, double h) {
    if (!(h > 0) || !std::isfinite(h))
        throw InvalidInputError("The resampling spacing h must be positive and finite.");
    Streamline out;
    out.backwardStop = line.backwardStop;
    out.forwardStop = line.forwardStop;
    if (line.points.empty()) return out;
    const Polyline2 fwd = resampleAtSpacing(line.forward(), h);
    const Polyline2 bwd = resampleAtSpacing(line.backward(), h);
    out.points.assign(bwd.rbegin(), bwd.rend());
    out.seedIndex = bwd.size() - 1;
    out.points.insert(out.points.end(), fwd.begin() + 1, fwd.end());
    return out;
}

} // namespace fss
