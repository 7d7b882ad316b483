#include "integrators/registry.h"

#include <algorithm>
#include <map>
#include <sstream>

namespace pl {

namespace {

// Constructed on first use: registrations run during static initialisation, in an order the
// language does not fix.
std::map<std::string, IntegratorEntry>& table() {
  static std::map<std::string, IntegratorEntry> entries;
  return entries;
}

}  // namespace

const ParamSpec* IntegratorEntry::budgetParam() const {
  for (const ParamSpec& p : params)
    if (p.budget) return &p;
  return nullptr;
}

IntegratorRegistration::IntegratorRegistration(IntegratorEntry entry) {
  std::string name = entry.name;
  table().emplace(std::move(name), std::move(entry));
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

std::string integratorsMarkdown() {
  std::ostringstream s;
  for (auto* e : integrators()) {
    s << "**`" << e->name << "`**: " << e->summary << ".\n\n";
    s << "| parameter | type | default | valid | meaning |\n|---|---|---|---|---|\n";
    for (const ParamSpec& p : e->params) {
      const char* type = p.type == ParamType::Integer ? "integer" : p.type == ParamType::Real ? "real" : "choice";
      std::string def = !p.defaultDoc.empty() ? p.defaultDoc : "`" + p.defaultValue + "`";
      if (p.budget) def += " (unlimited with `time` alone)";
      s << "| `" << p.name << "` (`" << p.flag() << "`) | " << type << " | " << def << " | " << p.range() << " | "
        << p.doc << " |\n";
    }
    s << "\n";
  }
  return s.str();
}

}  // namespace pl
