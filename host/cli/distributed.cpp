// Distributed rendering over MPI (host/cli/distributed.h). Only the wavepath executable compiles
// this file, with WP_HAVE_MPI when CMake found MPI; without it there is always one rank.
#include "host/cli/distributed.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#ifdef WP_HAVE_MPI
#include <mpi.h>
#endif

#include "host/util/error.h"

namespace wp {

namespace {

// A job of one: the part is the whole.
Reduced alone(RankPart part) {
  Reduced out;
  out.ok = part.error.empty() && part.film.has_value();
  out.error = std::move(part.error);
  out.details = std::move(part.details);
  if (part.film) out.film = std::move(*part.film);
  out.render_seconds = part.render_seconds;
  out.rays = part.rays;
  return out;
}

}  // namespace

bool mpi_built() {
#ifdef WP_HAVE_MPI
  return true;
#else
  return false;
#endif
}

Ranks::Slice Ranks::slice(int begin, int count) const {
  const int base = count / size_, extra = count % size_;
  Slice s;
  s.first = begin + rank_ * base + std::min(rank_, extra);
  s.samples = base + (rank_ < extra ? 1 : 0);
  return s;
}

#ifndef WP_HAVE_MPI

// Started by mpirun all the same: every process would render every sample and write the same
// outputs, which is never what was meant.
Ranks::Ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* size = std::getenv(name);
    if (size != nullptr && std::atoi(size) > 1)
      throw Error(std::string("started by an MPI launcher (") + name + "=" + size +
                  "), but this wavepath was built without MPI: each process would render "
                  "everything (install libopenmpi-dev and build again, or use --samples and "
                  "wavepath merge)");
  }
}

Ranks::~Ranks() = default;

bool Ranks::all(bool ok) const {
  return ok;
}

Reduced Ranks::reduce(RankPart part) const {
  return alone(std::move(part));
}

#else

namespace {

// The environment a launcher gives each process: Open MPI's mpirun, PMIx (srun --mpi=pmix,
// prterun), PMI (MPICH's hydra, srun --mpi=pmi2). Without one, MPI_Init would make a singleton
// job, which Open MPI can take seconds to set up, with warnings where there is no network.
bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

// MPI counts are ints: the words go in chunks of 2^27 (1 GiB), far below 2^31 elements.
constexpr std::size_t kChunkWords = std::size_t{1} << 27;
constexpr int kWordsTag = 1;

// What a rank tells rank 0 before any film is sent, as text: numbers in decimal and strings
// prefixed with their length, each field ended by '\n'.
struct Description {
  enum Kind : unsigned { kFilm, kEmpty, kFailed } kind = kEmpty;
  std::string error, details;
  double render_seconds = 0;
  std::uint64_t rays = 0;
  FilmInfo info;
  std::uint64_t words = 0;
};

void put(std::string& out, std::uint64_t v) {
  out += std::to_string(v);
  out += '\n';
}

void put(std::string& out, const std::string& s) {
  put(out, s.size());
  out += s;
  out += '\n';
}

std::string encode(const RankPart& part) {
  std::string out;
  const auto kind = !part.error.empty() ? Description::kFailed
                    : part.film ? Description::kFilm
                                : Description::kEmpty;
  put(out, kind);
  put(out, part.error);
  put(out, part.details);
  std::uint64_t seconds_bits = 0;
  static_assert(sizeof seconds_bits == sizeof part.render_seconds);
  std::memcpy(&seconds_bits, &part.render_seconds, sizeof seconds_bits);
  put(out, seconds_bits);
  put(out, part.rays);
  if (kind == Description::kFilm) {
    const FilmInfo& i = part.film->info();
    for (const std::uint64_t v :
         {std::uint64_t(i.width), std::uint64_t(i.height), std::uint64_t(i.sample_begin),
          std::uint64_t(i.sample_end), i.nonfinite_samples,
          std::uint64_t(part.film->words().size()), std::uint64_t(i.aov)})
      put(out, v);
    put(out, i.key);
    put(out, i.device);
  }
  return out;
}

// The reverse of encode. Its input comes from another rank of this same binary.
class Decoder {
 public:
  explicit Decoder(const std::string& text) : text_(text) {}
  std::uint64_t number() {
    const std::size_t end = text_.find('\n', at_);
    if (end == std::string::npos) throw Error("malformed rank description");
    const std::uint64_t v = std::strtoull(text_.c_str() + at_, nullptr, 10);
    at_ = end + 1;
    return v;
  }
  std::string text() {
    const std::size_t n = number();
    if (n > text_.size() - at_) throw Error("malformed rank description");
    std::string s = text_.substr(at_, n);
    at_ += n + 1;
    return s;
  }

 private:
  const std::string& text_;
  std::size_t at_ = 0;
};

Description decode(const std::string& text) {
  Decoder in(text);
  Description d;
  d.kind = static_cast<Description::Kind>(in.number());
  d.error = in.text();
  d.details = in.text();
  const std::uint64_t seconds_bits = in.number();
  std::memcpy(&d.render_seconds, &seconds_bits, sizeof seconds_bits);
  d.rays = in.number();
  if (d.kind == Description::kFilm) {
    d.info.width = static_cast<int>(in.number());
    d.info.height = static_cast<int>(in.number());
    d.info.sample_begin = static_cast<std::uint32_t>(in.number());
    d.info.sample_end = static_cast<std::uint32_t>(in.number());
    d.info.nonfinite_samples = in.number();
    d.words = in.number();
    d.info.aov = in.number() != 0;
    d.info.key = in.text();
    d.info.device = in.text();
  }
  return d;
}

// Every rank's description, on rank 0 (empty elsewhere).
std::vector<std::string> gather_descriptions(const std::string& mine, int rank, int size) {
  const int length = static_cast<int>(mine.size());
  std::vector<int> lengths(rank == 0 ? size : 0), offsets(lengths.size());
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string all;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = static_cast<int>(all.size());
    all.resize(all.size() + std::size_t(lengths[r]));
  }
  MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
              0, MPI_COMM_WORLD);
  std::vector<std::string> out;
  for (std::size_t r = 0; r < lengths.size(); ++r)
    out.push_back(all.substr(std::size_t(offsets[r]), std::size_t(lengths[r])));
  return out;
}

std::string rank_list(const std::vector<int>& ranks) {
  std::string out = ranks.size() == 1 ? "rank " : "ranks ";
  for (std::size_t i = 0; i < ranks.size(); ++i) out += (i ? ", " : "") + std::to_string(ranks[i]);
  return out;
}

// Rank 0's verdict on the descriptions: failures, or films that would not add up. An identical
// error on every rank (an unreadable scene, a bad option) reads as in a single process.
void judge(const std::vector<Description>& all, Reduced& out) {
  std::vector<std::pair<const Description*, std::vector<int> > > failures;  // distinct messages
  for (int r = 0; r < int(all.size()); ++r) {
    if (all[r].kind != Description::kFailed) continue;
    auto same = std::find_if(failures.begin(), failures.end(),
                             [&](const auto& f) { return f.first->error == all[r].error; });
    if (same == failures.end()) {
      failures.push_back({&all[r], {}});
      same = failures.end() - 1;
    }
    same->second.push_back(r);
  }
  if (!failures.empty()) {
    const auto line = [&](const auto& f) {
      return f.second.size() == all.size() ? f.first->error
                                           : rank_list(f.second) + ": " + f.first->error;
    };
    out.error = line(failures[0]);
    out.details = failures[0].first->details;
    for (std::size_t i = 1; i < failures.size(); ++i)
      out.details += (out.details.empty() ? "" : "\n") + ("wavepath: error: " + line(failures[i]));
    return;
  }
  int previous = -1;
  for (int r = 0; r < int(all.size()); ++r) {
    if (all[r].kind != Description::kFilm) continue;
    const FilmInfo& info = all[r].info;
    if (all[r].words !=
        std::uint64_t(info.width) * std::uint64_t(info.height) * info.words_per_pixel()) {
      out.error = "rank " + std::to_string(r) + ": its film's size does not match its data";
      return;
    }
    if (previous >= 0) {
      const std::string problem = film_merge_problem(all[previous].info, info);
      if (!problem.empty()) {
        // Different keys come from devices of different kinds (CPU and GPU pick different BVH
        // layouts): --bvh-width or --device makes them agree.
        out.error = "the films of ranks " + std::to_string(previous) + " and " + std::to_string(r) +
                    " do not merge: " + problem;
        return;
      }
    }
    previous = r;
  }
  if (previous < 0 || all[0].kind != Description::kFilm)
    out.error = "rank 0 rendered no samples";
  else
    out.ok = true;
}

void send_words(const std::vector<std::uint64_t>& words) {
  for (std::size_t at = 0; at < words.size(); at += kChunkWords)
    MPI_Send(words.data() + at, static_cast<int>(std::min(kChunkWords, words.size() - at)),
             MPI_UINT64_T, 0, kWordsTag, MPI_COMM_WORLD);
}

void receive_words(std::vector<std::uint64_t>& words, int from) {
  for (std::size_t at = 0; at < words.size(); at += kChunkWords)
    MPI_Recv(words.data() + at, static_cast<int>(std::min(kChunkWords, words.size() - at)),
             MPI_UINT64_T, from, kWordsTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

}  // namespace

Ranks::Ranks() {
  if (!launched_by_mpi()) return;
  MPI_Init(nullptr, nullptr);
  initialised_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  MPI_Comm_rank(node, &local_rank_);
  MPI_Comm_free(&node);
}

Ranks::~Ranks() {
  if (initialised_) MPI_Finalize();
}

bool Ranks::all(bool ok) const {
  if (size_ == 1) return ok;
  int mine = ok ? 1 : 0, every = 0;
  MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
  return every != 0;
}

Reduced Ranks::reduce(RankPart part) const {
  if (size_ == 1) return alone(std::move(part));
  const std::vector<std::string> texts = gather_descriptions(encode(part), rank_, size_);
  Reduced out;
  std::vector<Description> all;
  if (rank_ == 0) {
    try {
      for (const auto& t : texts) all.push_back(decode(t));
      for (const auto& d : all) {
        out.render_seconds = std::max(out.render_seconds, d.render_seconds);
        out.rays += d.rays;
      }
      judge(all, out);
    } catch (const std::exception& e) {
      out.ok = false;
      out.error = e.what();
    }
  }
  int ok = out.ok ? 1 : 0;
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  out.ok = ok != 0;
  if (!out.ok) return out;

  // From here on every rank has agreed to send or receive; a failure now (memory) cannot be
  // told to the others, so it ends the job.
  try {
    if (rank_ == 0) {
      out.film = std::move(*part.film);
      for (int r = 1; r < size_; ++r) {
        if (all[r].kind != Description::kFilm) continue;
        Film film(all[r].info);
        receive_words(film.words(), r);
        out.film.add(film);
      }
    } else if (part.film) {
      send_words(part.film->words());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wavepath: error: rank %d: %s\n", rank_, e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  return out;
}

#endif

}  // namespace wp
