// The documentation's reference pages, generated from the declarations they describe: the
// command line (CLI11's definitions), the integrators (the registry), the experiment TOML keys
// (experimentKeys) and the image metadata keys (metadataKeys). `photonlab reference PAGE` prints
// one; docs/pages/reference/PAGE.md is that output, and a test fails when the two differ.
#pragma once
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace pl {

// A subcommand's guide in the documentation, for its --help footer and the CLI page.
struct SubcommandDoc {
  std::string name;   // "render"
  std::string guide;  // "how-to/render-gltf.md": relative to docs/pages/
};
const std::vector<SubcommandDoc>& subcommandDocs();
// "Documentation: docs/pages/how-to/render-gltf.md (...)", for a subcommand's --help.
std::string helpFooter(const std::string& subcommand);

// The pages `photonlab reference` prints; throws Error for an unknown name.
std::vector<std::string> referencePageNames();
std::string referencePage(const std::string& name, CLI::App& app);

}  // namespace pl
