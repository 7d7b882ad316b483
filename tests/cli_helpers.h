// Running the photonlab binary from a test, as scripts and users do: exit code, stdout, stderr.
#pragma once
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "gltf_fixture.h"

namespace pl::test {

struct Result {
  int code;
  std::string out, err;
};

inline Result run(const std::string& args) {
  std::string dir = GltfFixture::dir();
  std::string cmd = std::string(PHOTONLAB_BINARY) + " " + args + " >" + dir + "/stdout.txt 2>" + dir + "/stderr.txt";
  int status = std::system(cmd.c_str());
  auto slurp = [](const std::string& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir + "/stdout.txt"), slurp(dir + "/stderr.txt")};
}

}  // namespace pl::test
