#include <gtest/gtest.h>
#include "continuum/nem/nem_solver.hpp"
#include "convergence_util.hpp"
using namespace arlequin; using namespace arlequin::continuum; using namespace arlequin::continuum::testing;
TEST(Debug, Nem) {
  for (std::string shape : {"sibson", "laplace"}) {
  ContinuumSettings st = settings("unit_cube.geo", 0.3, 1, Material::isotropic(1e3, 0.3, 1.0));
  st.shape_functions = shape;
  NemSolver s(st);
  for (int n = 0; n < s.num_nodes(); ++n) { Vec3 e = affine(s.nodes()[n]); for (int c=0;c<3;++c) s.displacement()[3*n+c]=e[c]; }
  Field f; s.internal_force(s.displacement(), f);
  const auto& bnd = s.mesh().group("boundary").nodes;
  double rmax=0; int worst=-1;
  for (int n = 0; n < s.num_nodes(); ++n) { if (std::binary_search(bnd.begin(), bnd.end(), n)) continue;
    double r = std::abs(f[3*n])+std::abs(f[3*n+1])+std::abs(f[3*n+2]); if (r>rmax) rmax=r, worst=n; }
  { double emax=0; int w=-1; auto E=s.point_strain(); for (size_t q=0;q<E.size();++q){ double d=(E[q]-affine_strain()).norm(); if(d>emax) emax=d,w=q;} std::cout<<"strain err "<<emax<<" at "<<w<<" x="<<s.nodes()[w].x<<","<<s.nodes()[w].y<<","<<s.nodes()[w].z<<"\n"; }
  std::cout << shape << " nodes " << s.num_nodes() << " interior residual max " << rmax << " at " << worst << " x=" << s.nodes()[worst].x<<","<<s.nodes()[worst].y<<","<<s.nodes()[worst].z<<"\n";
  auto N = s.interpolation({{0.5,0.5,1.0},{0.3,0.2,0.0}});
  for (int p=0;p<2;++p) for (InterpolationOperator::InnerIterator it(N,p); it; ++it) std::cout << p << " " << it.col() << " " << it.value() << " z=" << s.nodes()[it.col()].z << "\n";
  }
}
