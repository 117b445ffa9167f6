// Objects with known faces for the refinement's tests.
#pragma once

#include "core/object/articulated_object.h"
#include "core/object/families/primitives.h"

namespace bimart::test {

// A 40 × 40 cm slab `thickness` thick whose top face is z = 0 (bottom part; edges rounded by
// `radius`, vertices 1 cm apart: D points to the nearest object vertex, as on real objects)
// and a small lid far away.
inline ArticulatedObject slab(double thickness = 0.1, double radius = 0.005) {
  ArticulatedObject o;
  o.name = "slab";
  o.bottom = shapes::rounded_box({-0.2, -0.2, -thickness}, {0.2, 0.2, 0.0}, radius, 0.01);
  o.top = shapes::rounded_box({1.0, 1.0, 1.0}, {1.05, 1.05, 1.05}, 0.005, 0.01);
  return o;
}

// A closed box of 5 mm walls, 2·half_width square and 10 cm deep: five walls (bottom part)
// and a lid (top part) whose top face is z = 0.
inline ArticulatedObject hollow_box(double half_width) {
  ArticulatedObject o;
  o.name = "hollow_box";
  const double X = half_width, T = 0.005, Z = -0.1;
  shapes::append(o.bottom, shapes::rounded_box({-X, -X, Z}, {X, X, Z + T}, 0.001, 0.01));  // floor
  shapes::append(o.bottom, shapes::rounded_box({-X, -X, Z + T}, {-X + T, X, -T}, 0.001, 0.01));
  shapes::append(o.bottom, shapes::rounded_box({X - T, -X, Z + T}, {X, X, -T}, 0.001, 0.01));
  shapes::append(o.bottom, shapes::rounded_box({-X + T, -X, Z + T}, {X - T, -X + T, -T}, 0.001, 0.01));
  shapes::append(o.bottom, shapes::rounded_box({-X + T, X - T, Z + T}, {X - T, X, -T}, 0.001, 0.01));
  o.top = shapes::rounded_box({-X, -X, -T}, {X, X, 0.0}, 0.001, 0.01);
  return o;
}

}  // namespace bimart::test
