// SPDX-License-Identifier: GPL-3.0-or-later
// Shared by the OpenMP loops of the DEM and the continuum (built with ARLEQUIN_WITH_OPENMP;
// without it the pragmas are ignored and every loop runs on one thread).
#pragma once

#include <algorithm>
#include <vector>
#ifdef _OPENMP
#include <omp.h>
#endif

namespace arlequin {

// Loops of at most this many items run on one thread: below it, starting threads costs more
// than it saves.
inline constexpr long parallel_threshold = 4096;
// The same for the coupling's loops over its rows (a coupled DE's or a corrected node's three
// components, or a factor's row, gathered and scattered through an index list or a permutation;
// its sparse products keep parallel_threshold, on their entries): a row costs several times a
// plain per-DE update, so a loop of a thousand rows already takes several times what entering a
// parallel region costs (bench_omp_regions). The coupled fabric's 2 502 coupled DEs and the
// following DCB band's ~3 000 lie between the two bounds (docs/performance.md#coupling-rows).
inline constexpr long parallel_threshold_rows = 1024;
// The same for bonds, per colour of a bond set on average (dem::BondColouring). A bond costs
// 10-100 times a DE's update: a random packing's bond sets colour into ~20 colours of a few
// hundred to a few thousand bonds, which parallel_threshold would keep on one thread; 256 puts
// the 10k REV's sets on threads too (bench_bonded_block with cases/rev_elastic/case.yaml shows
// the gain; the figures are in the commit that set it).
inline constexpr long parallel_threshold_bonds = 256;
// ... and only in a scene of more DEs than this. Below it the DEs' state sits in one core's
// cache, and a second thread moves more of it between the cores than it takes bonds off the
// first: the coupled wave bar's lattice (775 DEs, 6 colours of ~330 bonds) steps faster with its
// bonds on one thread, while the all-DEM bar (2975 DEs, colours of ~1280 bonds) gains from the
// second (bench_coupled_step, bench_bonded_block).
inline constexpr long parallel_threshold_bond_particles = 2048;

// The threads an OpenMP loop may use (1 without OpenMP).
inline int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// The calling thread's number in its OpenMP team (0 outside a parallel region or without OpenMP).
inline int thread_index() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

// The number of threads in the calling thread's team (1 outside a parallel region).
inline int team_size() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

// Loops over the DEs split them in whole chunks of this many, the same chunks for every loop:
// small enough that a 10k-DE scene gives 16 threads ten chunks each (shares within a tenth of
// each other), large enough that a chunk of a per-DE vector array spans whole cache lines but
// at its two ends.
inline constexpr long share_chunk = 64;

struct IndexRange {
  long begin = 0, end = 0;
};

// The calling thread's share of `chunks` chunks: thread t of a team of T takes
// [t C / T, (t + 1) C / T). Every loop over the DEs (kicks, drift, clearing the forces, damping,
// the finite check, the beam sets' per-DE sums and their bonds' kernel pass) splits by this rule,
// so a thread works on the same DEs in every phase and their data stay in its core's cache; a
// split of each loop by its own index set (OpenMP's static schedule over DEs, over chunks of
// DEs, over a bond set's own DEs) moves the DEs near every boundary from core to core at each
// phase (docs/performance.md#one-owner). Outside a parallel region: all of them.
inline IndexRange chunk_share(long chunks) {
  const long threads = team_size(), t = thread_index();
  return {chunks * t / threads, chunks * (t + 1) / threads};
}

// The calling thread's share of the items [0, n), in whole chunks of share_chunk (chunk_share).
inline IndexRange thread_share(long n) {
  const IndexRange c = chunk_share((n + share_chunk - 1) / share_chunk);
  return {std::min(n, c.begin * share_chunk), std::min(n, c.end * share_chunk)};
}

// Whether a loop asked to run `threaded` does run on more than one thread.
inline bool runs_threaded(bool threaded) {
  return threaded && max_threads() > 1;
}

// Runs loop() on the OpenMP threads if `threaded` and there is more than one, else in the
// calling thread; loop() holds orphaned `omp for` loops, which split over the team inside the
// region and run whole outside it. Not entering OpenMP at all is the point: a parallel region
// whose `if` clause is false still starts a team of one, which costs about a hundred times an
// orphaned loop outside any region (bench_omp_regions prints both); a small coupled step enters
// several such regions, and paid for them a third of its time. Not for
// use inside a parallel region: an orphaned loop there would split over the enclosing team, or
// hang if only some of its threads reach it (none of ours nests).
template <class Loop>
void run_threaded_if(bool threaded, Loop&& loop) {
#ifdef _OPENMP
  if (runs_threaded(threaded)) {
#pragma omp parallel
    loop();
    return;
  }
#endif
  loop();
}

// body(i) for i in [0, n), split over the OpenMP threads by thread_share if `threaded`.
template <class Body>
void for_each_index(long n, bool threaded, Body&& body) {
  run_threaded_if(threaded, [n, &body] {
    const IndexRange share = thread_share(n);
    for (long i = share.begin; i < share.end; ++i) body(i);
  });
}

// Items [0, n) in fixed chunks of share_chunk: partial[c] = scan(begin, end) for chunk c, on the
// threads when n > threshold, each thread its chunk_share; returns the number of chunks. A
// caller that takes partial[0], partial[1], ... in order gets a result with the same bits on any
// thread count (an OpenMP reduction's does not). `partial` grows once and is reused (no
// allocation per call).
template <class T, class Scan>
long scan_fixed_chunks(long n, long threshold, std::vector<T>& partial, Scan&& scan) {
  constexpr long chunk = share_chunk;
  const long chunks = (n + chunk - 1) / chunk;
  if (static_cast<long>(partial.size()) < chunks) partial.resize(static_cast<std::size_t>(chunks));
  run_threaded_if(n > threshold, [&] {
    const IndexRange share = chunk_share(chunks);
    for (long c = share.begin; c < share.end; ++c) partial[static_cast<std::size_t>(c)] = scan(c * chunk, std::min(n, (c + 1) * chunk));
  });
  return chunks;
}

// partial[t] = scan(begin, end) over thread t's share (thread_share) of the items [0, n), on the
// threads when n > threshold; returns the number of shares, whose partials the caller combines.
// For reductions whose result does not depend on how the items are grouped (a largest value,
// whether any item is not finite): one partial per thread instead of one per chunk. Sums, whose
// round-off does, go through scan_fixed_chunks. A share no thread took keeps T{}, which must be
// the reduction's identity.
template <class T, class Scan>
long scan_thread_shares(long n, long threshold, std::vector<T>& partial, Scan&& scan) {
  const long shares = runs_threaded(n > threshold) ? max_threads() : 1;
  if (static_cast<long>(partial.size()) < shares) partial.resize(static_cast<std::size_t>(shares));
  std::fill(partial.begin(), partial.begin() + shares, T{});
  run_threaded_if(n > threshold, [&] {
    const IndexRange share = thread_share(n);
    partial[static_cast<std::size_t>(thread_index())] = scan(share.begin, share.end);
  });
  return shares;
}

// sum over i < n of term(i), each term evaluated once (it may update state of item i): the
// chunks of scan_fixed_chunks summed, then their sums added in order (the half kicks of a damped
// scene run through here).
template <class Term>
double fixed_order_sum(long n, long threshold, std::vector<double>& partial, Term&& term) {
  const long chunks = scan_fixed_chunks(n, threshold, partial, [&term](long begin, long end) {
    double sum = 0.0;
    for (long i = begin; i < end; ++i) sum += term(i);
    return sum;
  });
  double total = 0.0;
  for (long c = 0; c < chunks; ++c) total += partial[static_cast<std::size_t>(c)];
  return total;
}

}  // namespace arlequin
