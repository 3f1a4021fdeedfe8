#pragma once
/// \file scan_workspace.h
/// Memory that a series of scans reuses. An interactive session scans again and again at the same
/// resolution; each scan's CPU stages need a SampleGrid (~90 bytes per pixel), the Patch's arrays and
/// per-pixel scratch buffers (masks, triangle candidates, index maps). Allocating them fresh for every scan
/// makes the kernel fault in and clear every page on first touch, which at 100k-face sizes costs as much as
/// the computation itself (bench/scan_bench.cpp, counter `faults`). A ScanWorkspace keeps that memory
/// between scans: scratch buffers stay in it, and the grid and patch of a scan that is no longer needed are
/// handed back with recycle() so that a later scan fills them instead of allocating.
///
/// Results never depend on the workspace: a scan with a workspace (new, used or recycled into) gives
/// exactly the same grid and patch as one without. A workspace serves one scan at a time (it is not
/// thread-safe); the Session owns one.

#include <cstddef>
#include <memory>

namespace fss {

struct SampleGrid;
struct Patch;

/// Reusable storage of the scan stages (see the file comment). Movable, not copyable; a moved-from
/// workspace is empty and usable.
class ScanWorkspace {
public:
    ScanWorkspace();
    ~ScanWorkspace();
    ScanWorkspace(ScanWorkspace&&) noexcept;
    ScanWorkspace& operator=(ScanWorkspace&&) noexcept;
    ScanWorkspace(const ScanWorkspace&) = delete;
    ScanWorkspace& operator=(const ScanWorkspace&) = delete;

    /// Keeps the sample storage of \p grid for the next sampleRegularGrid with this workspace; \p grid is
    /// left empty (0 × 0, its samples cleared).
    void recycle(SampleGrid&& grid);
    /// Keeps the storage of \p patch (its mesh's arrays and vertexOfSample) for the next triangulateGrid
    /// with this workspace; \p patch is left valid but unspecified (it may hold an earlier recycled patch).
    /// A patch whose mesh was edited so that it has removed elements is not kept (left as it is).
    void recycle(Patch&& patch);
    /// Frees everything the workspace holds.
    void release();

    /// Internal: the buffers, for the scan stages (core/src/scan/scan_workspace_impl.h).
    struct Impl;
    Impl& impl();

private:
    std::unique_ptr<Impl> impl_;
};

} // namespace fss
