// Distributed rendering: the processes of an MPI job (`mpirun -np N wavepath render ...`) share
// one render's sample range. Rank r renders a contiguous slice of it; the films, whose sums are
// integers (host/film/film.h), are sent to rank 0 and added there, so the result is bit for bit the
// film of one process rendering the whole range. Only rank 0 writes outputs and prints.
//
// MPI is optional: without it (WP_HAVE_MPI undefined, see host/CMakeLists.txt), or when the
// process was not started by an MPI launcher, there is one rank and nothing here calls MPI.
// The same result without MPI, under any job scheduler: `render --samples A:B -o part.wpfilm` per
// job, then `wavepath merge`.
//
// Each rank renders its whole slice: a stop decided while rendering (a time limit, a noise
// threshold) would need the ranks to agree on where each stops, so that the slices still add up
// to one range without gaps.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "host/film/film.h"

namespace wp {

// What one rank brings to the reduction.
struct RankPart {
  std::optional<Film> film;  // none when the rank's slice is empty or it failed
  std::string error;         // why it failed (the line main() would print), or ""
  std::string details;       // and the lines after it (wp::Error::details)
  double render_seconds = 0;
  std::uint64_t rays = 0;
};

// The reduction's outcome, the same on every rank but for `film` and `error`.
struct Reduced {
  bool ok = false;  // every rank succeeded and the films belong together
  // Rank 0, when !ok: the first failure, prefixed with the ranks it happened on unless all, and
  // in `details` the others' (each distinct message once) and the first's details.
  std::string error, details;
  Film film;                  // rank 0, when ok: the films of all ranks added in sample order
  double render_seconds = 0;  // the slowest rank's: they render at the same time
  std::uint64_t rays = 0;     // all ranks'
};

class Ranks {
 public:
  // Joins the MPI job this process belongs to, when it was started by an MPI launcher (its
  // environment names a rank: mpirun, srun); otherwise one rank of one. A plain
  // `wavepath render` thus never initialises MPI, which could be slow or noisy on a machine
  // without a network.
  Ranks();
  ~Ranks();
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  // The rank among those on the same machine: which of its devices this rank takes.
  int local_rank() const { return local_rank_; }

  // This rank's part of the sample indices [begin, begin + count): contiguous slices in rank
  // order, the first count % size ranks one sample more, so that rank 0's slice is never empty.
  // Returns [first, first + samples); samples is 0 when count < size for the last ranks.
  struct Slice {
    int first = 0, samples = 0;
  };
  Slice slice(int begin, int count) const;

  // Collective: whether `ok` holds on every rank (a cheap agreement before long work).
  bool all(bool ok) const;

  // Collective: every rank calls it exactly once, whatever happened to it, so that a failure
  // anywhere ends the job everywhere instead of leaving ranks waiting. The ranks' descriptions
  // (or errors) go to rank 0 first, which checks that the films add up (film_merge_problem) and
  // tells every rank whether to go on; only then are the films' words sent, in chunks, and
  // added in rank order, which is sample order. Two films are held on rank 0 at a time.
  Reduced reduce(RankPart part) const;

 private:
  int rank_ = 0, size_ = 1, local_rank_ = 0;
  bool initialised_ = false;  // by us: we finalise
};

// Whether this binary was built with MPI.
bool mpi_built();

}  // namespace wp
