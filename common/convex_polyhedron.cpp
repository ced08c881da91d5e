// SPDX-License-Identifier: GPL-3.0-or-later
#include "common/convex_polyhedron.hpp"

#include <algorithm>
#include <cmath>

namespace arlequin {

namespace {

void drop_repeated(std::vector<Vec3>& pts, double tol) {
  std::vector<Vec3> out;
  for (const Vec3& p : pts)
    if (out.empty() || norm(p - out.back()) > tol) out.push_back(p);
  while (out.size() > 1 && norm(out.back() - out.front()) <= tol) out.pop_back();
  pts = std::move(out);
}

}  // namespace

Polyhedron box_polyhedron(const Vec3& a, const Vec3& b, int tag) {
  auto V = [&](int i, int j, int k) { return Vec3{i ? b.x : a.x, j ? b.y : a.y, k ? b.z : a.z}; };
  return {{{V(0, 0, 0), V(0, 1, 0), V(0, 1, 1), V(0, 0, 1)}, {-1, 0, 0}, tag},
          {{V(1, 0, 0), V(1, 0, 1), V(1, 1, 1), V(1, 1, 0)}, {1, 0, 0}, tag},
          {{V(0, 0, 0), V(0, 0, 1), V(1, 0, 1), V(1, 0, 0)}, {0, -1, 0}, tag},
          {{V(0, 1, 0), V(1, 1, 0), V(1, 1, 1), V(0, 1, 1)}, {0, 1, 0}, tag},
          {{V(0, 0, 0), V(1, 0, 0), V(1, 1, 0), V(0, 1, 0)}, {0, 0, -1}, tag},
          {{V(0, 0, 1), V(0, 1, 1), V(1, 1, 1), V(1, 0, 1)}, {0, 0, 1}, tag}};
}

bool clip(Polyhedron& poly, const Vec3& n, double d, int tag, double tol) {
  bool cuts = false;
  for (const PolyFace& f : poly)
    for (const Vec3& p : f.pts) cuts = cuts || dot(n, p) - d > tol;
  if (!cuts) return false;
  Polyhedron out;
  std::vector<Vec3> cap;
  for (const PolyFace& f : poly) {
    PolyFace g{{}, f.n, f.tag};
    const size_t m = f.pts.size();
    for (size_t k = 0; k < m; ++k) {
      const Vec3 &a = f.pts[k], &b = f.pts[(k + 1) % m];
      const double da = dot(n, a) - d, db = dot(n, b) - d;
      if (da <= tol) g.pts.push_back(a);
      if (std::abs(da) <= tol) cap.push_back(a);
      if ((da < -tol && db > tol) || (da > tol && db < -tol)) {
        const Vec3 x = a + (da / (da - db)) * (b - a);
        g.pts.push_back(x);
        cap.push_back(x);
      }
    }
    drop_repeated(g.pts, tol);
    if (g.pts.size() >= 3) out.push_back(std::move(g));
  }
  if (cap.size() >= 3) {
    Vec3 c{};
    for (const Vec3& p : cap) c += p;
    c = c / static_cast<double>(cap.size());
    const Vec3 e1 = normalized(std::abs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0}));
    const Vec3 e2 = cross(n, e1);
    std::sort(cap.begin(), cap.end(), [&](const Vec3& a, const Vec3& b) {
      return std::atan2(dot(a - c, e2), dot(a - c, e1)) < std::atan2(dot(b - c, e2), dot(b - c, e1));
    });
    drop_repeated(cap, tol);
    if (cap.size() >= 3) out.push_back({std::move(cap), n, tag});
  }
  poly = std::move(out);
  return true;
}

Vec3 vertex_centre(const PolyFace& f) {
  Vec3 c{};
  for (const Vec3& p : f.pts) c += p;
  return c / static_cast<double>(f.pts.size());
}

double volume(const Polyhedron& poly) {
  Vec3 apex{};
  int count = 0;
  for (const PolyFace& f : poly)
    for (const Vec3& p : f.pts) apex += p, ++count;
  if (count == 0) return 0.0;
  apex = apex / static_cast<double>(count);
  double v = 0.0;
  for (const PolyFace& f : poly) {
    const Vec3 c = vertex_centre(f);
    for (size_t k = 0; k < f.pts.size(); ++k)
      v += 0.5 * norm(cross(f.pts[k] - c, f.pts[(k + 1) % f.pts.size()] - c)) * dot(c - apex, f.n) / 3.0;
  }
  return v;
}

}  // namespace arlequin
