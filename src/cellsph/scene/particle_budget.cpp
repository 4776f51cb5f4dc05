#include "cellsph/scene/particle_budget.hpp"

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdio>

namespace cellsph::scene_detail {

double pairs_per_particle(int dim, double search_radius_in_spacings) {
  const double r = search_radius_in_spacings;
  return dim == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
}
double bytes_per_particle(double pairs) {
  return 256 + 8 * pairs;
}

ParticleBudget::ParticleBudget(int dim, double spacing, double radius, double memory) : spacing_(spacing) {
  limit_ = double(std::size_t{1} << 31);
  why_ = "2^31, the most particles a run can index";
  const double pairs = pairs_per_particle(dim, radius), bytes = bytes_per_particle(pairs);
  std::string whose = "this machine's";
  if (memory > 0) {
    whose = "the allowed";
  } else {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    memory = pages > 0 && page > 0 ? double(pages) * double(page) : 0;
  }
  if (memory > 0 && memory / bytes < limit_) {
    limit_ = memory / bytes;
    why_ = "what " + whose + " " + number(memory / double(1L << 30)) + " GiB of memory hold at about " +
           number(bytes) + " bytes a particle, which has " + number(pairs) + " neighbours within " +
           number(radius) + " spacings";
  }
  // A support of many spacings makes every particle costly: name that way out too.
  fix_ = radius > 8 ? "use a larger /spacing or a smaller /solver/support" : "use a larger /spacing";
}

void ParticleBudget::take_sites(double sites, const JsonReader& r, const std::string& key,
                                const std::string& what) const {
  if (sites > 64 * limit_)
    r.fail(key, "the bounding box of " + what + " spans " + number(sites) + " lattice sites at spacing " +
                    number(spacing_) + ", more than 64 times the particle limit " + number(limit_) + ": " +
                    fix_);
}

void ParticleBudget::check_reach(double far, int axis, const JsonReader& r, const std::string& key,
                                 const std::string& what) const {
  if (!(far / spacing_ < geometry::kMaxLatticeIndex))
    r.fail(key, what + " reaches " + number(far) + " m from the origin along axis " + std::to_string(axis) +
                    ", more than 2^50 spacings of " + number(spacing_) + " m: move it closer or use a " +
                    "coarser spacing");
}

void ParticleBudget::take(double count, const JsonReader& r, const std::string& key,
                          const std::string& what) {
  planned_ += count;
  if (planned_ > limit_)
    r.fail(key, "with " + what + " at spacing " + number(spacing_) + " m the scene has " + number(planned_) +
                    " particles, more than " + number(limit_) + " (" + why_ + "): " + fix_);
}

std::string ParticleBudget::number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

template <int Dim>
void budget_shape(ParticleBudget& budget, const geometry::Shape& s, double spacing, double margin,
                  double estimate, const JsonReader& r, const std::string& key, const std::string& what) {
  budget.take(estimate, r, key, what);
  budget.take_sites(geometry::lattice_sites(s, spacing, margin), r, key, what);
  // The lattice is anchored at the origin: a shape so far from it that its site indices pass 2^50 would
  // overflow them (and has no place in a scene at this spacing anyway).
  for (int a = 0; a < Dim; ++a) budget.check_reach(geometry::lattice_reach(s, margin, a), a, r, key, what);
}

template void budget_shape<2>(ParticleBudget&, const geometry::Shape&, double, double, double,
                              const JsonReader&, const std::string&, const std::string&);
template void budget_shape<3>(ParticleBudget&, const geometry::Shape&, double, double, double,
                              const JsonReader&, const std::string&, const std::string&);

}  // namespace cellsph::scene_detail
