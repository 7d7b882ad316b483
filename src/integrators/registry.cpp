#include "integrators/registry.h"

#include "integrators/builtins.h"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

namespace pl {

namespace {

void add(std::map<std::string, IntegratorEntry>& entries, IntegratorEntry entry) {
  if (entries.count(entry.name)) throw Error("integrator '" + entry.name + "' is registered twice");
  std::set<std::string> names;
  int budgets = 0;
  for (const ParamSpec& p : entry.params) {
    if (!names.insert(p.name).second) throw Error("integrator " + entry.name + ": parameter '" + p.name + "' is declared twice");
    budgets += p.budget;
    if (!p.defaultValue.empty()) {
      ParamSet probe(&entry.params);  // the default must pass its own validation
      try {
        probe.setText(p.name, p.defaultValue);
      } catch (const Error& e) {
        throw Error("integrator " + entry.name + ": the default of '" + p.name + "' is invalid: " + e.what());
      }
    }
  }
  if (budgets > 1) throw Error("integrator " + entry.name + ": more than one budget parameter");
  for (const std::string& r : entry.refinement) {
    auto p = std::find_if(entry.params.begin(), entry.params.end(), [&](const ParamSpec& s) { return s.name == r; });
    if (p == entry.params.end() || p->type != ParamType::Integer)
      throw Error("integrator " + entry.name + ": refinement parameter '" + r + "' is not a declared integer parameter");
  }
  if (entry.converges != Converges::kOther && entry.refinement.empty() && !entry.budgetParam())
    throw Error("integrator " + entry.name + ": it estimates radiance but has neither a budget nor a refinement parameter");
  if (!entry.sliceUnit.empty() && entry.sliceUnit != "spp" && entry.sliceUnit != "passes")
    throw Error("integrator " + entry.name + ": slice unit '" + entry.sliceUnit + "' is neither spp nor passes");
  std::string name = entry.name;
  entries.emplace(std::move(name), std::move(entry));
}

// Constructed on first use, holding the built-ins from the start (registrations of other
// integrators may run during static initialisation, in an order the language does not fix).
std::map<std::string, IntegratorEntry>& table() {
  static std::map<std::string, IntegratorEntry> entries = [] {
    std::map<std::string, IntegratorEntry> builtins;
    for (IntegratorEntry& e : builtinIntegrators()) add(builtins, std::move(e));
    return builtins;
  }();
  return entries;
}

}  // namespace

const ParamSpec* IntegratorEntry::budgetParam() const {
  for (const ParamSpec& p : params)
    if (p.budget) return &p;
  return nullptr;
}

const char* familyName(IntegratorFamily family) {
  switch (family) {
    case IntegratorFamily::Pixel: return "pixel";
    case IntegratorFamily::Pass: return "pass";
    case IntegratorFamily::LightPaths: return "light paths";
    case IntegratorFamily::Own: return "own loop";
  }
  return "?";
}

const char* convergesName(Converges converges) {
  switch (converges) {
    case Converges::kRadiance: return "radiance (every path up to the maximum depth)";
    case Converges::kDirectLighting: return "direct lighting (emission and one bounce of light at diffuse surfaces)";
    case Converges::kOther: return "no radiance (a quantity of its own)";
  }
  return "?";
}

IntegratorRegistration::IntegratorRegistration(IntegratorEntry entry) { add(table(), std::move(entry)); }

std::string integratorsSlicedBy(const std::string& unit) {
  std::string s;
  for (auto* e : integrators())
    if (e->sliceUnit == unit) s += (s.empty() ? "" : ", ") + e->name;
  return s;
}

std::string integratorsOfFamily(IntegratorFamily family) {
  std::string s;
  for (auto* e : integrators())
    if (e->family == family) s += (s.empty() ? "" : ", ") + e->name;
  return s;
}

std::vector<const IntegratorEntry*> integrators() {
  std::vector<const IntegratorEntry*> out;
  for (auto& [name, e] : table()) out.push_back(&e);
  return out;
}

const IntegratorEntry* findIntegrator(const std::string& name) {
  auto it = table().find(name);
  return it == table().end() ? nullptr : &it->second;
}

const IntegratorEntry& integratorEntry(const std::string& name) {
  const IntegratorEntry* e = findIntegrator(name);
  if (!e) throw Error("unknown integrator '" + name + "' (" + integratorList() + ")");
  return *e;
}

std::vector<std::string> integratorNames() {
  std::vector<std::string> names;
  for (auto* e : integrators()) names.push_back(e->name);
  return names;
}

std::string integratorList() {
  std::string s;
  for (auto& n : integratorNames()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string integratorsTaking(const std::string& param) {
  std::string s;
  for (auto* e : integrators())
    for (auto& p : e->params)
      if (p.name == param) s += (s.empty() ? "" : ", ") + e->name;
  return s;
}

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const ParamSet& params, const RenderOptions& image) {
  const IntegratorEntry& e = integratorEntry(name);
  if (&params.specs() != &e.params) throw Error("parameters of another integrator given to " + name);
  return e.make(params, image);
}

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const RenderOptions& image) {
  const IntegratorEntry& e = integratorEntry(name);
  return e.make(e.defaults(), image);
}

std::string integratorMarkdown(const IntegratorEntry& entry) {
  std::ostringstream s;
  {
    const IntegratorEntry* e = &entry;
    s << "**`" << e->name << "`**: " << e->summary << ".\n\n";
    static const char* const loops[] = {"the per-pixel loop", "passes of eye and photon paths", "the light-path loop",
                                        "a loop of its own"};
    s << "Driven by " << loops[int(e->family)] << "; "
      << (e->sliceUnit.empty() ? "cannot be sliced"
                               : std::string("sliced by ") + (e->sliceUnit == "spp" ? "`--sample-range`" : "`--pass-range`"))
      << ".\n\n";
    s << "Converges to " << convergesName(e->converges);
    if (e->converges != Converges::kOther) {
      static const char* const kinds[] = {"point and spot lights", "directional lights", "area lights", "the environment"};
      std::vector<std::string> carried, missing;
      for (int t = 0; t < 4; ++t) ((e->carries & lightTypeBit(LightType(t))) ? carried : missing).push_back(kinds[t]);
      auto join = [](const std::vector<std::string>& v) {
        std::string out;
        for (const std::string& x : v) out += (out.empty() ? "" : ", ") + x;
        return out;
      };
      s << "; carries " << join(carried) << (missing.empty() ? "" : " (not " + join(missing) + ")");
    }
    s << ".\n\n";
    s << "| parameter | type | default | valid | meaning |\n|---|---|---|---|---|\n";
    for (const ParamSpec& p : e->params) {
      const char* type = p.type == ParamType::Integer ? "integer" : p.type == ParamType::Real ? "real" : "choice";
      std::string def = !p.defaultDoc.empty() ? p.defaultDoc : "`" + p.defaultValue + "`";
      if (p.budget) def += " (unlimited with `time` alone)";
      s << "| `" << p.name << "` (`" << p.flag() << "`) | " << type << " | " << def << " | " << p.range() << " | "
        << markdownText(p.doc) << " |\n";
    }
    s << "\n";
  }
  return s.str();
}

std::string markdownText(const std::string& text) {
  std::string s;
  bool code = false;
  for (char c : text) {
    code = code != (c == '`');
    s += !code && c == '<' ? "&lt;" : !code && c == '>' ? "&gt;" : std::string(1, c);
  }
  return s;
}

std::string integratorsMarkdown() {
  std::string s;
  for (auto* e : integrators()) s += integratorMarkdown(*e);
  return s;
}

}  // namespace pl
