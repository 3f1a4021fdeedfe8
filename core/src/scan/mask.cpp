#include "fss/mask.h"

#include "fss/error.h"
#include "fss/raycast.h"

#include "base/parallel_rows.h"
#include "scan/scan_workspace_impl.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <barrier>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <string>
#include <utility>

namespace fss {
namespace {

using Point2 = Kernel::Point_2;

// A sample this close to the face under its pixel (in pixel footprints) is taken to lie on it.
constexpr double kOnFaceFootprints = 1e-3;

// The lasso's edges bucketed into horizontal bands, so a point query only visits the edges whose
// y-range can contain the point's y. Floating-point band indices are monotone in y, so an edge whose
// y-range contains y is always found in y's band.
class LassoIndex {
public:
    explicit LassoIndex(const Lasso& lasso) {
        if (lasso.points.empty()) return; // encloses nothing (validateLasso rejects it)
        points_.reserve(lasso.points.size());
        for (const Eigen::Vector2d& p : lasso.points)
            points_.emplace_back(p.x(), p.y());
        const auto [xmin, xmax] = std::minmax_element(lasso.points.begin(), lasso.points.end(),
                                                      [](auto& a, auto& b) { return a.x() < b.x(); });
        const auto [ymin, ymax] = std::minmax_element(lasso.points.begin(), lasso.points.end(),
                                                      [](auto& a, auto& b) { return a.y() < b.y(); });
        x0_ = xmin->x();
        x1_ = xmax->x();
        y0_ = ymin->y();
        y1_ = ymax->y();
        const std::size_t m = points_.size();
        bandCount_ = int(std::clamp<std::size_t>(m / 2, 1, 1024));
        bandHeight_ = (y1_ - y0_) / bandCount_;
        bands_.resize(std::size_t(bandCount_));
        for (std::size_t i = 0; i < m; ++i) {
            const Point2& a = points_[i];
            const Point2& b = points_[(i + 1) % m];
            const int lo = band(std::min(a.y(), b.y())), hi = band(std::max(a.y(), b.y()));
            for (int k = lo; k <= hi; ++k)
                bands_[std::size_t(k)].push_back(std::uint32_t(i));
        }
    }

    // Non-zero winding rule (Sunday's crossing form of the winding number), boundary inside.
    bool inside(const Eigen::Vector2d& q) const {
        if (points_.empty()) return false;
        if (!(q.x() >= x0_ && q.x() <= x1_ && q.y() >= y0_ && q.y() <= y1_)) return false;
        const Point2 p(q.x(), q.y());
        const std::size_t m = points_.size();
        int winding = 0;
        for (std::uint32_t i : bands_[std::size_t(band(q.y()))]) {
            const Point2& a = points_[i];
            const Point2& b = points_[(i + 1) % m];
            const CGAL::Orientation o = CGAL::orientation(a, b, p);
            if (o == CGAL::COLLINEAR && std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
                std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y()))
                return true; // on the boundary
            if (a.y() <= p.y()) {
                if (b.y() > p.y() && o == CGAL::LEFT_TURN) ++winding;
            } else if (b.y() <= p.y() && o == CGAL::RIGHT_TURN) {
                --winding;
            }
        }
        return winding != 0;
    }

    // inside() for every point of a row: points (xs[j], y), xs non-decreasing and finite, y finite; out[j]
    // = 1 when inside, else 0. The same exact decisions as inside() point by point: for a fixed y, the
    // orientation of an edge's line towards (x, y) is the sign of a linear function of x, so along the row
    // it changes at most twice (left, collinear, right, or the reverse); binary searches with the exact
    // predicate find those places, and each edge adds its winding to a range of the row. O(k log n + n)
    // for k edges in the row's band instead of O(k n) predicates.
    void insideRow(const std::vector<double>& xs, double y, std::vector<std::uint8_t>& out,
                   std::vector<int>& diff) const {
        const std::size_t n = xs.size();
        out.assign(n, 0);
        if (points_.empty() || n == 0 || !(y >= y0_ && y <= y1_)) return;
        diff.assign(n + 1, 0);
        std::vector<std::uint8_t>& boundary = out; // set to 2 where a point lies on an edge
        const std::size_t m = points_.size();
        for (std::uint32_t i : bands_[std::size_t(band(y))]) {
            const Point2& a = points_[i];
            const Point2& b = points_[(i + 1) % m];
            auto orient = [&](std::size_t j) { return CGAL::orientation(a, b, Point2(xs[j], y)); };
            // First index in [0, n) where pred holds, pred being monotone (false … false true … true).
            auto firstWhere = [&](auto pred) {
                std::size_t lo = 0, hi = n;
                while (lo < hi) {
                    const std::size_t mid = lo + (hi - lo) / 2;
                    if (pred(orient(mid)))
                        hi = mid;
                    else
                        lo = mid + 1;
                }
                return lo;
            };
            // The orientation as a function of x has the sign of −(b.y − a.y): decreasing when the edge
            // goes up in y (left, collinear, right), increasing when it goes down, constant when level.
            std::size_t collinearBegin = 0, collinearEnd = 0;
            if (b.y() > a.y()) {
                collinearBegin = firstWhere([](CGAL::Orientation o) { return o != CGAL::LEFT_TURN; });
                collinearEnd = firstWhere([](CGAL::Orientation o) { return o == CGAL::RIGHT_TURN; });
                if (a.y() <= y && b.y() > y) { // left turns count +1
                    diff[0] += 1;
                    diff[collinearBegin] -= 1;
                }
            } else if (b.y() < a.y()) {
                collinearBegin = firstWhere([](CGAL::Orientation o) { return o != CGAL::RIGHT_TURN; });
                collinearEnd = firstWhere([](CGAL::Orientation o) { return o == CGAL::LEFT_TURN; });
                if (b.y() <= y) { // a.y > y here is implied by the case below; right turns count −1
                    if (a.y() > y) {
                        diff[0] -= 1;
                        diff[collinearBegin] += 1;
                    }
                }
            } else if (orient(0) == CGAL::COLLINEAR) { // level edge on the row's line
                collinearBegin = 0;
                collinearEnd = n;
            }
            const double xmin = std::min(a.x(), b.x()), xmax = std::max(a.x(), b.x());
            const double ymin = std::min(a.y(), b.y()), ymax = std::max(a.y(), b.y());
            if (ymin <= y && y <= ymax)
                for (std::size_t j = collinearBegin; j < collinearEnd; ++j)
                    if (xmin <= xs[j] && xs[j] <= xmax) boundary[j] = 2;
        }
        int winding = 0;
        for (std::size_t j = 0; j < n; ++j) {
            winding += diff[j];
            const bool inBox = xs[j] >= x0_ && xs[j] <= x1_;
            out[j] = inBox && (boundary[j] == 2 || winding != 0) ? 1 : 0;
        }
    }

private:
    int band(double y) const {
        if (!(bandHeight_ > 0)) return 0;
        return std::clamp(int(std::floor((y - y0_) / bandHeight_)), 0, bandCount_ - 1);
    }

    std::vector<Point2> points_;
    double x0_ = 0, x1_ = 0, y0_ = 0, y1_ = 0, bandHeight_ = 0;
    int bandCount_ = 1;
    std::vector<std::vector<std::uint32_t>> bands_;
};

void requireRadius(int radius) {
    if (radius < 0)
        throw InvalidInputError("The morphology radius " + std::to_string(radius) + " is negative.");
}

void requireGridShape(const SampleGrid& grid) {
    if (grid.rows < 0 || grid.cols < 0 ||
        grid.samples.size() != std::size_t(grid.rows) * std::size_t(grid.cols))
        throw InvalidInputError("The sample grid holds " + std::to_string(grid.samples.size()) +
                                " samples instead of its " + std::to_string(grid.rows) + "x" +
                                std::to_string(grid.cols) + ".");
}

} // namespace

void validateLasso(const Lasso& lasso) {
    for (const Eigen::Vector2d& p : lasso.points)
        if (!p.allFinite()) throw InvalidInputError("The lasso has a point with a non-finite coordinate.");
    std::vector<std::pair<double, double>> distinct;
    for (const Eigen::Vector2d& p : lasso.points)
        distinct.emplace_back(p.x(), p.y());
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    if (distinct.size() < 3)
        throw InvalidInputError("The lasso has " + std::to_string(distinct.size()) +
                                " distinct points; it needs at least 3 to enclose an area.");
    const Point2 a(distinct[0].first, distinct[0].second), b(distinct[1].first, distinct[1].second);
    for (std::size_t i = 2; i < distinct.size(); ++i)
        if (CGAL::orientation(a, b, Point2(distinct[i].first, distinct[i].second)) != CGAL::COLLINEAR) return;
    throw InvalidInputError("The lasso's points all lie on one line, so it encloses no area.");
}

bool insideLasso(const Lasso& lasso, const Eigen::Vector2d& p) {
    return LassoIndex(lasso).inside(p);
}

std::size_t applyLasso(SampleGrid& grid, const Lasso& lasso) {
    validateLasso(lasso);
    const LassoIndex index(lasso);
    // Rows in blocks, one per thread; each sample is decided on its own (parallel.h).
    const int blocks = detail::rowBlocks(grid.rows, 16);
    std::vector<std::size_t> dropped(std::size_t(blocks), 0);
    detail::parallelRows(grid.rows, blocks, [&](int block, int rowBegin, int rowEnd) {
        std::vector<double> xs;
        std::vector<std::uint8_t> inside;
        std::vector<int> diff;
        for (int r = rowBegin; r < rowEnd; ++r) {
            Sample* row = grid.samples.data() + grid.index(r, 0);
            const std::size_t n = std::size_t(grid.cols);
            // A row of one finite y and non-decreasing finite x (every regular grid) is decided at once;
            // any other row (fishbone grids) sample by sample. Both give inside()'s exact answers.
            bool asRow = n > 0 && std::isfinite(row[0].screen.y());
            xs.resize(n);
            for (std::size_t j = 0; j < n && asRow; ++j) {
                xs[j] = row[j].screen.x();
                asRow = row[j].screen.y() == row[0].screen.y() && std::isfinite(xs[j]) &&
                        (j == 0 || xs[j - 1] <= xs[j]);
            }
            if (asRow) index.insideRow(xs, row[0].screen.y(), inside, diff);
            for (std::size_t j = 0; j < n; ++j) {
                Sample& s = row[j];
                if (!s.admissible || (asRow ? inside[j] != 0 : index.inside(s.screen))) continue;
                s.admissible = s.valid = false;
                ++dropped[std::size_t(block)];
            }
        }
    });
    return std::accumulate(dropped.begin(), dropped.end(), std::size_t(0));
}

std::size_t applyQualityMask(SampleGrid& grid, const Mesh& current, const FrameBuffers& currentBuffers,
                             const QualityMaskOptions& options) {
    requireGridShape(grid);
    if (currentBuffers.width() != grid.camera.width || currentBuffers.height() != grid.camera.height)
        throw InvalidInputError("The current mesh's buffers are " + std::to_string(currentBuffers.width()) +
                                "x" + std::to_string(currentBuffers.height()) +
                                " but the scan camera's image is " + std::to_string(grid.camera.width) + "x" +
                                std::to_string(grid.camera.height) +
                                ": they must be rendered from the scan camera.");
    const std::size_t n = std::size_t(currentBuffers.width()) * std::size_t(currentBuffers.height());
    if (currentBuffers.faceId.size() != n)
        throw InvalidInputError("The current mesh's face-id buffer holds " +
                                std::to_string(currentBuffers.faceId.size()) + " values instead of " +
                                std::to_string(n) + ".");
    options.validate();
    if (options.forceReplace) return 0;

    const auto [qualityMap, hasQuality] = current.property_map<FaceIndex, float>(props::faceQuality);
    const LocalSearchOptions search{.rings = options.searchRings, .verifyUnoccluded = false};
    // Rows in blocks, one per thread; each sample is decided on its own (parallel.h).
    const int blocks = detail::rowBlocks(grid.rows, 16);
    std::vector<std::size_t> dropped(std::size_t(blocks), 0);
    detail::parallelRows(grid.rows, blocks, [&](int block, int rowBegin, int rowEnd) {
        // Row by row: first the faces under the row's admissible samples (one entry per run of samples
        // over the same face, as neighbouring samples mostly share it), then those faces' corners and
        // qualities — lookups in the current mesh that do not depend on each other, so the processor
        // overlaps their cache misses — then the samples' tests.
        struct HintFace {
            FaceIndex face;
            std::array<Eigen::Vector3d, 3> corner;
            float quality = kInputFaceQuality;
        };
        std::vector<HintFace> hints;
        std::vector<std::uint32_t> hintOf(std::size_t(grid.cols));
        constexpr std::uint32_t kNoHint = std::uint32_t(-1);
        for (int r = rowBegin; r < rowEnd; ++r) {
            Sample* row = grid.samples.data() + grid.index(r, 0);
            hints.clear();
            for (int c = 0; c < grid.cols; ++c) {
                hintOf[std::size_t(c)] = kNoHint;
                const Sample& s = row[c];
                if (!s.admissible) continue;
                const double fx = std::floor(s.screen.x()), fy = std::floor(s.screen.y());
                if (!(fx >= 0 && fy >= 0 && fx < currentBuffers.width() && fy < currentBuffers.height()))
                    continue;
                const std::uint32_t id = currentBuffers.faceAt(int(fx), int(fy));
                if (id == FrameBuffers::kNoFace) continue;
                const FaceIndex hint(id);
                if (hints.empty() || hints.back().face != hint) {
                    if (std::size_t(id) >= current.num_faces() || current.is_removed(hint))
                        throw InvalidInputError("The current mesh's face-id buffer names face " +
                                                std::to_string(id) +
                                                ", which the current mesh does not have.");
                    hints.push_back({hint, {}, kInputFaceQuality});
                }
                hintOf[std::size_t(c)] = std::uint32_t(hints.size() - 1);
            }
            // Without qualities every face has kInputFaceQuality: no need to know which is closest.
            if (hasQuality) {
                for (HintFace& hf : hints) {
                    const HalfedgeIndex h = current.halfedge(hf.face);
                    for (const auto& [corner, v] :
                         {std::pair{0, current.source(h)}, std::pair{1, current.target(h)},
                          std::pair{2, current.target(current.next(h))}}) {
                        const Point3& p = current.point(v);
                        hf.corner[std::size_t(corner)] = {p.x(), p.y(), p.z()};
                    }
                    hf.quality = qualityMap[hf.face];
                }
            }
            for (int c = 0; c < grid.cols; ++c) {
                if (hintOf[std::size_t(c)] == kNoHint) continue;
                Sample& s = row[c];
                const HintFace& hf = hints[hintOf[std::size_t(c)]];
                float faceQ = kInputFaceQuality;
                if (hasQuality) {
                    // Fast path: the sample lies on the face under its pixel (up to rounding), as almost
                    // always where the current mesh is the reference; any closer face is closer by less.
                    const Eigen::Vector3d q =
                        closestPointOnTriangle(s.point, hf.corner[0], hf.corner[1], hf.corner[2]);
                    if ((q - s.point).norm() <= kOnFaceFootprints * double(s.footprint))
                        faceQ = hf.quality;
                    else
                        faceQ = qualityMap[closestPointNear(current, s.point, hf.face, search).face];
                }
                if (std::isnan(faceQ)) faceQ = kInputFaceQuality;
                if (double(s.quality) < (1.0 - options.margin) * double(faceQ)) continue;
                s.admissible = s.valid = false;
                ++dropped[std::size_t(block)];
            }
        }
    });
    return std::accumulate(dropped.begin(), dropped.end(), std::size_t(0));
}

namespace {

// The morphology works on one byte per sample (a Sample is ~90 bytes: every pass over the grid's
// samples streams all of them through memory), in the buffers of a ScanWorkspace: valid, admissible and
// original (valid as read, so that only the samples that changed are written back), and square and
// counts as scratch.
using Scratch = ScanWorkspace::Impl;

// A block of whole rows [rowBegin, rowEnd) of a rows × cols byte grid, and a way to wait until every
// block has reached the same point: the steps below run on all blocks at once (one thread each,
// parallel.h), each step writing only its block's rows and reading other rows only after a sync().
// Every result is the serial one.
struct RowBlock {
    int rows, cols, rowBegin, rowEnd;
    const std::function<void()>& sync;
    std::vector<int>& count; // scratch of cols entries, the block's own
    std::size_t begin() const { return std::size_t(rowBegin) * std::size_t(cols); }
    std::size_t end() const { return std::size_t(rowEnd) * std::size_t(cols); }
};

// Runs step(block) on row blocks of the grid, one thread each, and returns the sum of what they return.
// Everything is allocated before the blocks start: a step must not throw (the others would wait for it).
template <class Step> std::size_t inRowBlocks(int rows, int cols, Step&& step) {
    const int blocks = detail::rowBlocks(rows, 64);
    std::barrier barrier(blocks);
    const std::function<void()> sync = [&barrier] { barrier.arrive_and_wait(); };
    std::vector<std::size_t> sums(std::size_t(blocks), 0);
    std::vector<std::vector<int>> counts(std::size_t(blocks),
                                         std::vector<int>(std::size_t(std::max(cols, 0))));
    detail::parallelRows(rows, blocks, [&](int b, int rowBegin, int rowEnd) {
        sums[std::size_t(b)] = step(RowBlock{rows, cols, rowBegin, rowEnd, sync, counts[std::size_t(b)]});
    });
    return std::accumulate(sums.begin(), sums.end(), std::size_t(0));
}

// out = pred(number of set entries of `in` in the window [c − radius, c + radius] of the same row),
// entries outside the grid counting as unset, for the block's rows.
template <class Pred>
void rowWindows(const RowBlock& b, const std::vector<std::uint8_t>& in, int radius,
                std::vector<std::uint8_t>& out, Pred pred) {
    const int cols = b.cols;
    for (int r = b.rowBegin; r < b.rowEnd; ++r) {
        const std::uint8_t* row = in.data() + std::size_t(r) * std::size_t(cols);
        std::uint8_t* o = out.data() + std::size_t(r) * std::size_t(cols);
        int count = 0;
        for (int i = 0; i < std::min(radius, cols); ++i)
            count += row[i];
        for (int i = 0; i < cols; ++i) {
            if (i + radius < cols) count += row[i + radius];
            if (i - radius - 1 >= 0) count -= row[i - radius - 1];
            o[i] = pred(count) ? 1 : 0;
        }
    }
}

// visit(index, count) for the block's entries, count = number of set entries of `in` in the window
// [r − radius, r + radius] of the same column (outside the grid unset); row by row, one running count per
// column, so memory is read in order.
template <class Visit>
void columnWindows(const RowBlock& b, const std::vector<std::uint8_t>& in, int radius, Visit visit) {
    const int rows = b.rows, cols = b.cols;
    std::vector<int>& count = b.count;
    std::fill(count.begin(), count.end(), 0);
    auto addRow = [&](int r, int sign) {
        const std::uint8_t* row = in.data() + std::size_t(r) * std::size_t(cols);
        for (int c = 0; c < cols; ++c)
            count[std::size_t(c)] += sign * row[c];
    };
    // The window of the row before the block: rows [rowBegin − radius − 1, rowBegin + radius − 1].
    for (int r = std::max(b.rowBegin - radius - 1, 0); r < std::min(b.rowBegin + radius, rows); ++r)
        addRow(r, 1);
    for (int i = b.rowBegin; i < b.rowEnd; ++i) {
        if (i + radius < rows) addRow(i + radius, 1);
        if (i - radius - 1 >= 0) addRow(i - radius - 1, -1);
        const std::size_t base = std::size_t(i) * std::size_t(cols);
        for (int c = 0; c < cols; ++c)
            visit(base + std::size_t(c), count[std::size_t(c)]);
    }
}

// Reads valid (and admissible when \p withAdmissible) of the block's samples into f.valid, f.original
// and f.admissible.
void readFlags(const RowBlock& b, const SampleGrid& grid, Scratch& f, bool withAdmissible) {
    for (std::size_t i = b.begin(); i < b.end(); ++i) {
        const Sample& s = grid.samples[i];
        f.valid[i] = f.original[i] = s.valid ? 1 : 0;
        if (withAdmissible) f.admissible[i] = s.admissible ? 1 : 0;
    }
}

// Writes f.valid back into the block's samples where it differs from what was read.
void writeChangedFlags(const RowBlock& b, SampleGrid& grid, const Scratch& f) {
    for (std::size_t i = b.begin(); i < b.end(); ++i)
        if (f.valid[i] != f.original[i]) grid.samples[i].valid = f.valid[i] != 0;
}

void sizeScratch(Scratch& f, std::size_t n, bool withAdmissible) {
    f.valid.resize(n); // every entry is written before it is read
    f.original.resize(n);
    f.square.resize(n);
    if (withAdmissible) f.admissible.resize(n);
}

std::size_t erodeBlock(const RowBlock& b, std::vector<std::uint8_t>& valid, int radius, Scratch& scratch) {
    if (radius == 0) return 0;
    const long long side = 2LL * radius + 1;
    std::size_t removed = 0;
    if (side > std::min(b.rows, b.cols)) { // no square fits in the grid
        for (std::size_t i = b.begin(); i < b.end(); ++i)
            removed += std::exchange(valid[i], std::uint8_t(0));
        b.sync();
        return removed;
    }
    // Separable: a full square = full rows of full columns.
    std::vector<std::uint8_t>& rowsFull = scratch.square;
    rowWindows(b, valid, radius, rowsFull, [side](int n) { return n == side; });
    b.sync();
    columnWindows(b, rowsFull, radius, [&](std::size_t i, int n) {
        if (valid[i] && n != side) valid[i] = 0, ++removed;
    });
    b.sync();
    return removed;
}

std::size_t dilateBlock(const RowBlock& b, std::vector<std::uint8_t>& valid,
                        const std::vector<std::uint8_t>& admissible, int radius, Scratch& scratch) {
    if (radius == 0) return 0;
    radius = std::min(radius, std::max(b.rows, b.cols)); // larger squares cover the grid all the same
    std::vector<std::uint8_t>& rowsAny = scratch.square;
    rowWindows(b, valid, radius, rowsAny, [](int n) { return n > 0; });
    b.sync();
    std::size_t added = 0;
    columnWindows(b, rowsAny, radius, [&](std::size_t i, int n) {
        if (!valid[i] && admissible[i] && n > 0) valid[i] = 1, ++added;
    });
    b.sync();
    return added;
}

std::size_t removeUntriangulatableBlock(const RowBlock& b, std::vector<std::uint8_t>& valid,
                                        Scratch& scratch) {
    const int rows = b.rows, cols = b.cols;
    std::size_t removed = 0;
    if (rows < 2 || cols < 2) {
        for (std::size_t i = b.begin(); i < b.end(); ++i)
            removed += std::exchange(valid[i], std::uint8_t(0));
        b.sync();
        return removed;
    }
    auto at = [&](int r, int c) { return valid[std::size_t(r) * std::size_t(cols) + std::size_t(c)]; };
    // quadFull(r, c): the quad with top-left corner (r, c) has four valid corners (stored at sample (r, c)).
    const int qr = rows - 1, qc = cols - 1;
    std::vector<std::uint8_t>& quadFull = scratch.square;
    for (int r = b.rowBegin; r < std::min(b.rowEnd, qr); ++r)
        for (int c = 0; c < qc; ++c)
            quadFull[std::size_t(r) * std::size_t(cols) + std::size_t(c)] =
                at(r, c) && at(r, c + 1) && at(r + 1, c) && at(r + 1, c + 1);
    b.sync();
    auto full = [&](int r, int c) {
        return r >= 0 && c >= 0 && r < qr && c < qc &&
               quadFull[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
    };
    for (int r = b.rowBegin; r < b.rowEnd; ++r) {
        for (int c = 0; c < cols; ++c) {
            std::uint8_t& v = valid[std::size_t(r) * std::size_t(cols) + std::size_t(c)];
            if (v && !full(r - 1, c - 1) && !full(r - 1, c) && !full(r, c - 1) && !full(r, c)) {
                v = 0;
                ++removed;
            }
        }
    }
    b.sync();
    return removed;
}

} // namespace

std::size_t erode(SampleGrid& grid, int radius) {
    requireRadius(radius);
    requireGridShape(grid);
    Scratch f;
    sizeScratch(f, grid.samples.size(), false);
    return inRowBlocks(grid.rows, grid.cols, [&](const RowBlock& b) {
        readFlags(b, grid, f, false);
        b.sync();
        const std::size_t removed = erodeBlock(b, f.valid, radius, f);
        writeChangedFlags(b, grid, f);
        return removed;
    });
}

std::size_t dilate(SampleGrid& grid, int radius) {
    requireRadius(radius);
    requireGridShape(grid);
    Scratch f;
    sizeScratch(f, grid.samples.size(), true);
    return inRowBlocks(grid.rows, grid.cols, [&](const RowBlock& b) {
        readFlags(b, grid, f, true);
        b.sync();
        const std::size_t added = dilateBlock(b, f.valid, f.admissible, radius, f);
        writeChangedFlags(b, grid, f);
        return added;
    });
}

std::size_t removeUntriangulatableSamples(SampleGrid& grid) {
    requireGridShape(grid);
    Scratch f;
    sizeScratch(f, grid.samples.size(), false);
    return inRowBlocks(grid.rows, grid.cols, [&](const RowBlock& b) {
        readFlags(b, grid, f, false);
        b.sync();
        const std::size_t removed = removeUntriangulatableBlock(b, f.valid, f);
        writeChangedFlags(b, grid, f);
        return removed;
    });
}

MorphologyReport applyMorphology(SampleGrid& grid, const MorphologyOptions& options) {
    ScanWorkspace workspace;
    return applyMorphology(grid, options, workspace);
}

MorphologyReport applyMorphology(SampleGrid& grid, const MorphologyOptions& options,
                                 ScanWorkspace& workspace) {
    requireRadius(options.radius);
    if (options.dilateRadius < -1)
        throw InvalidInputError("The dilation radius " + std::to_string(options.dilateRadius) +
                                " is negative.");
    requireGridShape(grid);
    const int dilateRadius = options.dilateRadius < 0 ? options.radius : options.dilateRadius;
    // One read of the samples for all three steps, and one write of those that changed.
    Scratch& f = workspace.impl();
    sizeScratch(f, grid.samples.size(), true);
    std::array<std::atomic<std::size_t>, 3> changed{};
    inRowBlocks(grid.rows, grid.cols, [&](const RowBlock& b) {
        readFlags(b, grid, f, true);
        b.sync();
        changed[0] += erodeBlock(b, f.valid, options.radius, f);
        changed[1] += dilateBlock(b, f.valid, f.admissible, dilateRadius, f);
        changed[2] += removeUntriangulatableBlock(b, f.valid, f);
        writeChangedFlags(b, grid, f);
        return std::size_t(0);
    });
    MorphologyReport report;
    report.eroded = changed[0];
    report.restored = changed[1];
    report.untriangulatable = changed[2];
    return report;
}

} // namespace fss
