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

namespace {

// One half being traced, one attempted RK4 step at a time, the step split into its stages (begin: the
// first evaluation when not reused; the three further stages; end: the evaluation at the step's end, the
// stop tests, accept or retry). Tracing two halves stage by stage in lockstep (traceTwoHalves) puts their
// independent field evaluations next to each other, so the processor overlaps their chains of dependent
// loads, square roots and divisions; each half's result is exactly the same as traced alone.
class HalfTracer {
public:
    HalfTracer(const DirectionField& field, const Eigen::Vector2d& seed,
               const Eigen::Vector2d& initialDirection, const StreamlineOptions& options)
        : tracer_(field, options), o_(options), seed_(seed),
          cosMaxTurn_(std::cos(options.maxTurnDeg * std::numbers::pi / 180.0)), step_(options.step) {
        options.validate();
        if (!seed.allFinite() || !initialDirection.allFinite() || initialDirection.isZero())
            throw InvalidInputError("A streamline needs a finite seed and a non-zero initial direction.");
        const Evaluation start = tracer_.evaluate(seed, initialDirection);
        if (!start.direction)
            throw InvalidInputError("The streamline seed " + pointName(seed) +
                                    " lies where the direction field is undefined (background, image border, "
                                    "outside the region or too low anisotropy).");
        startDirection_ = previous_ = *start.direction;
        half_.points.push_back(seed);
        p_ = seed;
    }

    bool done() const { return done_; }

    // Starts an attempted step: the stop tests before it, its length and the field at p.
    void begin() {
        if (done_) return;
        if (steps_ >= o_.maxSteps) return finish(StreamlineStop::StepLimit);
        remaining_ = o_.maxLength - half_.length;
        if (remaining_ <= 0) return finish(StreamlineStop::MaxLength);
        last_ = remaining_ <= step_;
        h_ = last_ ? remaining_ : step_;
        if (!atP_) atP_ = tracer_.evaluate(p_, previous_);
    }
    // The RK4 stages, every evaluation aligned with the previous step's direction.
    void stage2() {
        if (done_) return;
        k2_ = atP_->direction ? tracer_.evaluate(p_ + 0.5 * h_ * *atP_->direction, previous_) : *atP_;
    }
    void stage3() {
        if (done_) return;
        k3_ = k2_.direction ? tracer_.evaluate(p_ + 0.5 * h_ * *k2_.direction, previous_) : k2_;
    }
    void stage4() {
        if (done_) return;
        k4_ = k3_.direction ? tracer_.evaluate(p_ + h_ * *k3_.direction, previous_) : k3_;
    }
    // Ends the attempted step: accepted (the half grows by one point) or retried with half the step.
    void end() {
        if (done_) return;
        std::optional<StreamlineStop> failure;
        Eigen::Vector2d delta = Eigen::Vector2d::Zero();
        if (!k4_.direction) {
            failure = k4_.reason;
        } else {
            delta = (h_ / 6.0) *
                    (*atP_->direction + 2.0 * *k2_.direction + 2.0 * *k3_.direction + *k4_.direction);
            if (!(delta.norm() > 0)) failure = StreamlineStop::SharpTurn;
        }
        if (!failure && last_) delta *= remaining_ / delta.norm(); // end exactly at maxLength
        Eigen::Vector2d q = p_ + delta;
        std::optional<Evaluation> atQ;
        if (!failure) {
            // Aligned with the new heading: if the step is accepted this is the next step's k1.
            atQ = tracer_.evaluate(q, delta);
            if (!atQ->direction)
                failure = atQ->reason;
            else if (delta.normalized().dot(previous_) < cosMaxTurn_)
                failure = StreamlineStop::SharpTurn;
        }
        if (failure) {
            if (h_ > o_.minStep) {
                step_ = std::max(o_.minStep, 0.5 * h_);
                return;
            }
            return finish(*failure);
        }

        // Accept the step, moved onto the attracting curve when there is one nearby.
        if (o_.attractor && !last_) {
            if (const std::optional<Eigen::Vector2d> a = o_.attractor(q, delta.normalized());
                a && a->allFinite() && (*a - p_).norm() > 1e-9) {
                const Eigen::Vector2d moved = *a - p_;
                if (Evaluation e = tracer_.evaluate(*a, moved); e.direction && moved.dot(previous_) > 0) {
                    q = *a;
                    delta = moved;
                    atQ = std::move(e);
                }
            }
        }
        const double len = delta.norm();
        half_.points.push_back(q);
        half_.length += len;
        previous_ = delta / len;
        ++steps_;
        if (last_) {
            half_.length = o_.maxLength;
            return finish(StreamlineStop::MaxLength);
        }
        // Closed integral curve: the step passed the seed again, heading the way it started.
        if (half_.length > 8.0 * o_.step) {
            const double t = std::clamp((seed_ - p_).dot(delta) / (len * len), 0.0, 1.0);
            if ((p_ + t * delta - seed_).norm() < 0.5 * o_.step && previous_.dot(startDirection_) > 0)
                return finish(StreamlineStop::Closed);
        }
        p_ = q;
        atP_ = std::move(atQ);
        step_ = std::min(o_.step, 2.0 * step_);
    }

    StreamlineHalf take() { return std::move(half_); }

private:
    void finish(StreamlineStop reason) {
        half_.stop = reason;
        done_ = true;
    }

    Tracer tracer_;
    const StreamlineOptions& o_;
    Eigen::Vector2d seed_, startDirection_, p_, previous_;
    double cosMaxTurn_, step_;
    double remaining_ = 0, h_ = 0; // of the attempted step
    bool last_ = false;            // the attempted step ends at maxLength
    std::size_t steps_ = 0;
    // The field at p aligned with `previous`: the last accepted step's end evaluation is exactly the next
    // step's first (same position, same reference), so each step costs four field samples, not five.
    std::optional<Evaluation> atP_;
    Evaluation k2_, k3_, k4_;
    StreamlineHalf half_;
    bool done_ = false;
};

} // namespace

StreamlineHalf traceStreamlineHalf(const DirectionField& field, const Eigen::Vector2d& seed,
                                   const Eigen::Vector2d& initialDirection,
                                   const StreamlineOptions& options) {
    HalfTracer t(field, seed, initialDirection, options);
    while (!t.done()) {
        t.begin();
        t.stage2();
        t.stage3();
        t.stage4();
        t.end();
    }
    return t.take();
}

std::vector<StreamlineHalf> traceHalvesInLockstep(const DirectionField& field,
                                                  const std::vector<HalfStart>& starts,
                                                  const StreamlineOptions& options) {
    std::vector<HalfTracer> tracers;
    tracers.reserve(starts.size());
    for (const HalfStart& s : starts)
        tracers.emplace_back(field, s.seed, s.initialDirection, options);
    auto all = [&](void (HalfTracer::*stage)()) {
        for (HalfTracer& t : tracers)
            (t.*stage)();
    };
    while (std::any_of(tracers.begin(), tracers.end(), [](const HalfTracer& t) { return !t.done(); })) {
        all(&HalfTracer::begin);
        all(&HalfTracer::stage2);
        all(&HalfTracer::stage3);
        all(&HalfTracer::stage4);
        all(&HalfTracer::end);
    }
    std::vector<StreamlineHalf> out;
    out.reserve(tracers.size());
    for (HalfTracer& t : tracers)
        out.push_back(t.take());
    return out;
}

Streamline traceStreamline(const DirectionField& field, const Eigen::Vector2d& seed,
                           const StreamlineOptions& options, const Eigen::Vector2d& preferredDirection) {
    options.validate();
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
