#pragma once
/// \file shapes.h
/// Small analytic meshes with exactly known properties, for tests, benchmarks and examples.
/// All are consistently oriented with outward normals (closed shapes) or +z normals (grids).

#include "fss/mesh.h"

namespace fss::shapes {

/// Regular triangulated grid of (nx × ny) quads over [0, nx·h] × [0, ny·h] in the z = 0 plane, each quad
/// split along the same diagonal: every interior vertex has valence exactly 6.
Mesh grid(int nx, int ny, double h = 1.0);

/// Regular icosahedron inscribed in a sphere of the given radius: 12 vertices of valence 5, all angles 60°.
Mesh icosahedron(double radius = 1.0);

/// Icosphere: icosahedron subdivided \p levels times (each triangle into 4), projected to the sphere.
Mesh icosphere(int levels, double radius = 1.0);

/// Latitude/longitude sphere with poles (nu around, nv from pole to pole).
Mesh uvSphere(int nu, int nv, double radius = 1.0);

/// Closed cylinder around the z axis from z = 0 to z = height, nu around, nv along, capped with fans.
Mesh cylinder(int nu, int nv, double radius = 1.0, double height = 2.0, bool capped = true);

/// Torus around the z axis: major radius R (centre of the tube), minor radius r; nu around the axis,
/// nv around the tube.
Mesh torus(int nu, int nv, double majorRadius = 1.0, double minorRadius = 0.3);

/// Axis-aligned cube [-s/2, s/2]^3 with n × n quads per side (each split into two triangles).
Mesh cube(int n = 1, double side = 1.0);

} // namespace fss::shapes
