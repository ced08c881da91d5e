// SPDX-License-Identifier: GPL-3.0-or-later
// dcb_arms_coarse.geo's arms as one body: the layers fused, every node of the mid-plane shared
// (layout in dcb_arms_layout.geo). The reference of the tests of joined bodies
// (tests/continuum/test_joined_bodies.cpp): the two arms of dcb_arms_coarse.geo, joined over the
// whole mid-plane, are this mesh.
nx = 46; ny = 7; nz = 2; fused = 1;
Include "dcb_arms_layout.geo";
