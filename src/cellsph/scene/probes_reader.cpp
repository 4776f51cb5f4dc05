// /probes and /probes_every (docs/scenes.md, "probes and probes_every"): what a run samples into
// probes.csv.
#include "cellsph/scene/scene_readers.hpp"

namespace cellsph::scene_detail {

template <int Dim>
void read_probes(JsonReader& r, std::vector<Probe>& probes, double& every) {
  every = r.number("probes_every", every, 1e-9, 1e9);
  if (!r.has("probes")) return;
  const auto& pj = r.json()["probes"];
  if (!pj.is_array())
    r.fail("probes", "expected an array of {\"name\", \"kind\", \"at\"}, got " + json_value_text(pj));
  auto list = r.child("probes");
  std::vector<std::string> taken{"time"};
  for (std::size_t k = 0; k < list.array_size(); ++k) {
    auto e = list.element(k);
    Probe pr;
    if (!e.has("name")) e.fail("name", "required: the probe's column name in probes.csv");
    pr.name = e.string("name", "");
    if (pr.name.empty() || pr.name.find_first_of(",\"\r\n") != std::string::npos)
      e.fail("name", "'" + pr.name + "' is not a CSV column name (non-empty, no comma, quote or line break)");
    for (const auto& c : probe_columns({pr}, Dim))
      for (const auto& t : taken)
        if (c == t) e.fail("name", "'" + pr.name + "' gives the column '" + c + "', which is already taken");
    if (!e.has("kind")) e.fail("kind", "required: pressure, level, layer or velocity");
    pr.kind = *parse_probe_kind(e.choice("kind", "pressure", {"pressure", "level", "layer", "velocity"}));
    const auto at = e.required_vector("at", Dim);
    for (std::size_t a = 0; a < Dim; ++a) pr.at[a] = at[a];
    e.finish();
    for (const auto& c : probe_columns({pr}, Dim)) taken.push_back(c);
    probes.push_back(std::move(pr));
  }
}

template void read_probes<2>(JsonReader&, std::vector<Probe>&, double&);
template void read_probes<3>(JsonReader&, std::vector<Probe>&, double&);

}  // namespace cellsph::scene_detail
