// The command line as other tools call it: exit codes, one-line errors, no output file left
// behind on failure, and the JSON of `compare`.
#include <catch2/catch.hpp>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_helpers.h"
#include "gltf_fixture.h"
#include "integrator_helpers.h"
#include "scene/gltf_loader.h"

using namespace pl;
using namespace pl::test;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

void expectCleanFailure(const std::string& args, const std::string& output, const std::string& mentions) {
  fs::remove(output);
  Result r = run(args);
  INFO(args << "\n" << r.err);
  CHECK(r.code == 1);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);  // exactly one line
  CHECK_THAT(r.err, Contains(mentions));
  CHECK_FALSE(fs::exists(output));
  if (fs::is_directory(fs::path(output).parent_path()))
    for (auto& e : fs::directory_iterator(fs::path(output).parent_path()))
      CHECK(e.path().filename().string().find(".partial-") == std::string::npos);
}

}  // namespace

TEST_CASE("cli: render writes EXR and PNG - leaves no temporary file") {
  GltfFixture f;
  std::string scene = f.write("cli.gltf"), dir = GltfFixture::dir();
  Result r = run("render " + scene + " -o " + dir + "/a.exr -o " + dir + "/a.png --width 8 --spp 2 --threads 2");
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(fs::file_size(dir + "/a.exr") > 0);
  CHECK(fs::file_size(dir + "/a.png") > 0);
  Result c = run("compare " + dir + "/a.exr " + dir + "/a.exr");
  REQUIRE(c.code == 0);
  CHECK(nlohmann::json::parse(c.out) == nlohmann::json::parse(R"({"rmse":0,"relmse":0,"mae":0,"mean_ratio":1})"));
}

TEST_CASE("cli: bad input gives one line - exit 1 - and no output file") {
  GltfFixture f;
  std::string scene = f.write("cli-errors.gltf"), dir = GltfFixture::dir(), out = dir + "/never.exr";
  expectCleanFailure("render " + dir + "/missing.gltf -o " + out, out, "missing.gltf");
  expectCleanFailure("render " + GltfFixture::writeText("broken.gltf", "{") + " -o " + out, out, "broken.gltf");
  expectCleanFailure("render " + scene + " -o " + out + " --integrator nope", out, "--integrator");
  expectCleanFailure("render " + scene + " -o " + out + " --spp 0", out, "--spp");
  expectCleanFailure("render " + scene + " -o " + out + " --width -5", out, "--width");
  expectCleanFailure("render " + scene + " -o " + out + " --time -1", out, "--time");
  expectCleanFailure("render " + scene + " -o " + out + " --spp abc", out, "--spp");
  expectCleanFailure("render " + scene + " -o " + out + " --no-such-flag", out, "no-such-flag");
  expectCleanFailure("render " + scene + " -o " + dir + "/never.jpg", dir + "/never.jpg", ".exr or .png");
  expectCleanFailure("render " + scene + " -o " + dir + "/no/such/dir/x.exr", dir + "/no/such/dir/x.exr", "does not exist");
  std::string photon = "render " + scene + " -o " + out + " --integrator photon ";
  expectCleanFailure("render " + scene + " -o " + out + " --camera 1", out, "--camera");
  expectCleanFailure("render " + scene + " -o " + out + " --camera -1", out, "--camera");
  expectCleanFailure(photon + "--kernel gauss", out, "--kernel");
  expectCleanFailure(photon + "--photons -5", out, "--photons");
  expectCleanFailure(photon + "--k 0", out, "--k");
  expectCleanFailure(photon + "--radius -1", out, "--radius");
  expectCleanFailure(photon + "--max-radius nan", out, "--max-radius");
  expectCleanFailure(photon + "--final-gather -1", out, "--final-gather");
  expectCleanFailure(photon + "--aov depth", out, "--aov");
  expectCleanFailure("render " + scene + " -o " + out + " --aov photons", out, "--aov");
  // An option the chosen integrator does not take is refused (as in an experiment's TOML), not ignored.
  expectCleanFailure("render " + scene + " -o " + out + " --alpha 0.5", out, "--alpha: is not a parameter of integrator path");
  expectCleanFailure("render " + scene + " -o " + out + " --integrator sppm --spp 4", out,
                     "--spp: is not a parameter of integrator sppm");
  expectCleanFailure("render " + scene + " -o " + out + " --integrator sppm --alpha 1.5", out,
                     "--alpha: must be in (0, 1], got 1.5");
  // Values that used to fall back silently to a default, or wrapped around.
  expectCleanFailure("render " + scene + " -o " + out + " --width 0", out, "--width: must be at least 1 pixel, got 0");
  expectCleanFailure("render " + scene + " -o " + out + " --height 0", out, "--height: must be at least 1 pixel");
  expectCleanFailure("render " + scene + " -o " + out + " --time 0", out, "--time: must be a number of seconds above 0");
  expectCleanFailure("render " + scene + " -o " + out + " --seed -1", out, "--seed: must be 0 or more, got -1");
  // An unknown integrator lists them all (sorted by name: the registry's order).
  Result u = run("render " + scene + " -o " + out + " --integrator metropolis");
  CHECK(u.code == 1);
  CHECK_THAT(u.err, Contains("unknown integrator 'metropolis' (bdpt, bpm, direct, guided, light, path, photon, ppm, pppm, radiosity, sppm, vcm, whitted)"));
  Result c = run("compare " + dir + "/nothing.exr " + dir + "/nothing.exr");
  CHECK(c.code == 1);
  CHECK_THAT(c.err, Contains("nothing.exr"));
  // An sRGB PNG against a linear EXR is refused (their numbers would mean nothing); two PNGs are
  // compared after decoding sRGB, and the output says so.
  REQUIRE(run("render " + scene + " --width 8 --spp 1 -q -o " + dir + "/cmp.exr -o " + dir + "/cmp.png").code == 0);
  Result mixed = run("compare " + dir + "/cmp.png " + dir + "/cmp.exr");
  CHECK(mixed.code == 1);
  CHECK(std::count(mixed.err.begin(), mixed.err.end(), '\n') == 1);
  CHECK_THAT(mixed.err, Contains("cmp.png: an 8-bit display image (sRGB, clamped to [0, 1]) cannot be compared with the linear"));
  Result pngs = run("compare " + dir + "/cmp.png " + dir + "/cmp.png");
  CHECK(pngs.code == 0);
  CHECK(nlohmann::json::parse(pngs.out)["decoded_srgb"] == true);
  CHECK_THAT(pngs.err, Contains("decoding sRGB to linear"));
  expectCleanFailure("render " + scene + " -o " + out + " --tonemap filmic", out, "--tonemap: unknown tone curve 'filmic' (clamp, aces)");
  expectCleanFailure("render " + scene + " -o " + out + " --exposure nan", out, "--exposure");
}

TEST_CASE("cli: photonlab alone prints its usage") {
  Result r = run("");
  CHECK(r.code == 0);
  CHECK_THAT(r.out, Contains("render"));
  CHECK_THAT(r.out, Contains("compare"));
  CHECK_THAT(r.out, Contains("Usage"));
}

TEST_CASE("cli: a file without a camera renders from the automatic view - info describes a file without lights") {
  GltfFixture f;
  f.doc["scenes"][0]["nodes"] = {0, 2};  // floor and light, no camera
  std::string dir = GltfFixture::dir();
  Result r = run("render " + f.write("cli-nocamera.gltf") + " -o " + dir + "/nocamera.exr --width 16 --spp 4 --threads 2");
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK_THAT(r.err, Contains("automatic three-quarter view"));
  CHECK(fs::file_size(dir + "/nocamera.exr") > 0);
  // The floor, the whole scene, is in the middle of the view, lit; the corners, outside the
  // bounding sphere's disc (27° from the axis against the disc's 20°), see nothing.
  auto scene = loadGltf(f.write("cli-nocamera.gltf"));
  RenderOptions ro;
  ro.width = ro.height = 16;
  ro.spp = 4;
  ImageRGB image = makeWith("path", {{"spp", 4}})->render(*scene, ro, nullptr);
  auto at = [&](int x, int y) { return image.data[3 * (size_t(y) * 16 + x)]; };
  CHECK(at(8, 8) > 0);
  CHECK(at(0, 0) == 0);
  CHECK(at(15, 15) == 0);
  GltfFixture g;
  g.doc["scenes"][0]["nodes"] = {0, 1};  // floor and camera, no light
  Result i = run("info " + g.write("cli-nolight.gltf"));
  INFO(i.err);
  REQUIRE(i.code == 0);
  CHECK_THAT(i.out, Contains("cameras: 1 in the file"));
  CHECK_THAT(i.out, Contains("0: nodes[1], cameras[0]"));
  CHECK_THAT(i.out, Contains("lights: 1"));
  CHECK_THAT(i.out, Contains("environment: default environment: overcast sky (CIE), mean radiance 1, 1, 1 W/(m2 sr)"));
  Result e = run("render " + g.write("cli-nolight.gltf") + " -o " + dir + "/nolight.exr --spp 1 --width 8");
  INFO(e.err);
  CHECK(e.code == 0);
  CHECK_THAT(e.err, Contains("no light") && Contains("default environment"));
}

TEST_CASE("cli: info reports the lights' power in watts") {
  GltfFixture f;
  Result r = run("info " + f.write("cli-info.gltf"));
  REQUIRE(r.code == 0);
  CHECK_THAT(r.out, Contains("triangles: 2"));
  CHECK_THAT(r.out, Contains("point"));
  CHECK_THAT(r.out, Contains("25.1327"));  // 4π · 2 W/sr
}

TEST_CASE("cli: progressive checkpoints after passes 1 - 2 - 4 and the last - with metadata") {
  GltfFixture f;
  std::string scene = f.write("cli-progressive.gltf"), dir = GltfFixture::dir();
  Result r = run("render " + scene + " --integrator sppm --passes 5 --photons-per-pass 2000 --width 8 --checkpoints -q -o " +
                 dir + "/prog.exr");
  INFO(r.err);
  REQUIRE(r.code == 0);
  for (const char* suffix : {".pass-0001", ".pass-0002", ".pass-0004", ".pass-0005", ""}) {
    std::string path = dir + "/prog" + suffix + ".exr";
    REQUIRE(fs::exists(path));
    Result m = run("info " + path);
    REQUIRE(m.code == 0);
    auto meta = nlohmann::json::parse(m.out);
    CHECK(meta["integrator"] == "sppm");
    // Numbers are JSON numbers, text is JSON strings.
    REQUIRE(meta["passes"].is_number_integer());
    int passes = meta["passes"].get<int>();
    CHECK(meta["photons"] == passes * 2000);
    CHECK(meta["radius"].get<double>() > 0);
    CHECK(meta["initial_radius"].get<double>() > 0);
    CHECK(meta["seconds"].get<double>() >= 0);
    CHECK(meta["seed"] == 1);
    CHECK(meta["width"] == 8);
  }
  CHECK_FALSE(fs::exists(dir + "/prog.pass-0003.exr"));
  expectCleanFailure("render " + scene + " --checkpoints -o " + dir + "/nope.exr", dir + "/nope.exr", "--checkpoints");
  expectCleanFailure("render " + scene + " --integrator pppm --alpha 0 -o " + dir + "/nope.exr", dir + "/nope.exr", "--alpha");
}

TEST_CASE("cli: info records the radius actually used - resolved defaults - as numbers") {
  GltfFixture f;
  std::string scene = f.write("cli-radius.gltf"), dir = GltfFixture::dir();
  // Photon mapping with k-NN: the default cap, 5% of the scene's bounding radius (the bounds are
  // the floor [−1, 1]² at y = 0: a radius of √2), and the mean k-NN radius, which lies below it.
  Result r = run("render " + scene + " --integrator photon --photons 20000 --caustic-photons 0 --final-gather 0 --width 8 --spp 1 -q -o " +
                 dir + "/radius.exr");
  INFO(r.err);
  REQUIRE(r.code == 0);
  auto meta = nlohmann::json::parse(run("info " + dir + "/radius.exr").out);
  CHECK(meta["radius"] == 0);
  const double expectedCap = 0.05 * std::sqrt(2.0);
  CHECK(meta["max_radius"].get<double>() == Approx(expectedCap).epsilon(1e-4));
  CHECK(meta["mean_radius"].get<double>() > 0);
  CHECK(meta["mean_radius"].get<double>() <= meta["max_radius"].get<double>());
  // A fixed radius is what it says.
  r = run("render " + scene + " --integrator photon --radius 0.02 --photons 20000 --width 8 --spp 1 -q -o " + dir + "/radius.exr");
  REQUIRE(r.code == 0);
  meta = nlohmann::json::parse(run("info " + dir + "/radius.exr").out);
  CHECK(meta["radius"] == Approx(0.02));
  CHECK(meta["mean_radius"] == Approx(0.02));
}

TEST_CASE("cli: impossible photon counts and resolutions are one-line errors before any work") {
  GltfFixture f;
  std::string scene = f.write("cli-memory.gltf"), dir = GltfFixture::dir();
  ::setenv("PHOTONLAB_MEMORY_LIMIT", "100000000", 1);  // pretend 100 MB are free
  expectCleanFailure("render " + scene + " --integrator photon --photons 4000000000 -o " + dir + "/m.exr", dir + "/m.exr",
                     "photon paths: needs");
  expectCleanFailure("render " + scene + " --width 20000 -o " + dir + "/m.exr", dir + "/m.exr", "20000x20000 image: needs");
  ::unsetenv("PHOTONLAB_MEMORY_LIMIT");
}

TEST_CASE("cli: --aov nan writes the non-finite-sample image with its metadata - not for progressive methods") {
  GltfFixture f;
  std::string scene = f.write("cli-nan.gltf"), dir = GltfFixture::dir();
  Result r = run("render " + scene + " --aov nan --width 8 --spp 4 -q -o " + dir + "/nan.exr");
  INFO(r.err);
  REQUIRE(r.code == 0);
  Result m = run("info " + dir + "/nan.exr");
  CHECK_THAT(m.out, Contains("\"aov\": \"nan\""));
  expectCleanFailure("render " + scene + " --integrator sppm --aov nan -o " + dir + "/nan2.exr", dir + "/nan2.exr", "--aov nan");
}

TEST_CASE("cli: --spectral renders with every integrator family and says so in the metadata") {
  GltfFixture f;
  std::string scene = f.write("cli-spectral.gltf"), dir = GltfFixture::dir();
  // Each with its own options: the CLI refuses an option the integrator does not take.
  const std::map<std::string, std::string> options = {{"path", "--spp 2"},
                                                      {"light", "--spp 2"},
                                                      {"photon", "--spp 2 --photons 2000 --caustic-photons 0"},
                                                      {"sppm", "--passes 2 --photons-per-pass 2000"}};
  for (auto& [integrator, args] : options) {
    std::string out = dir + "/spectral-" + integrator + ".exr";
    Result r = run("render " + scene + " --spectral --integrator " + integrator + " --width 8 " + args + " -q -o " + out);
    INFO(integrator << "\n" << r.err);
    REQUIRE(r.code == 0);
    Result m = run("info " + out);
    CHECK_THAT(m.out, Contains("\"spectral\": 1"));
  }
}

TEST_CASE("cli: --env lights a scene - a radiance or a map - and its mistakes are one-line errors") {
  GltfFixture g;
  g.doc["scenes"][0]["nodes"] = {0, 1};  // floor and camera, no light
  std::string scene = g.write("cli-env.gltf"), dir = GltfFixture::dir(), out = dir + "/env.exr";
  Result r = run("render " + scene + " -o " + out + " --env 0.2,0.4,0.6 --width 8 --spp 2");
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(r.err.find("default environment") == std::string::npos);  // --env replaces the default
  Result i = run("info " + out);
  CHECK_THAT(i.out, Contains("\"environment\": \"constant 0.2, 0.4, 0.6 W/(m2 sr)\""));
  // Any image photonlab reads serves as a map: this render, say.
  Result m = run("render " + scene + " -o " + dir + "/env-map.exr --env " + out + " --env-rotate 90 --env-scale 3 --width 8 --spp 2");
  INFO(m.err);
  REQUIRE(m.code == 0);
  CHECK_THAT(run("info " + dir + "/env-map.exr").out, Contains("\"environment\": \"map " + out + ", rotated 90 deg, scale 3\""));
  const std::string never = dir + "/never-env.exr";
  expectCleanFailure("render " + scene + " -o " + never + " --env -1", never, "--env: radiance must be finite and >= 0");
  expectCleanFailure("render " + scene + " -o " + never + " --env 1,2", never, "--env: expected R,G,B");
  expectCleanFailure("render " + scene + " -o " + never + " --env " + dir + "/no-sky.exr", never, "--env: file not found: " + dir + "/no-sky.exr");
  expectCleanFailure("render " + scene + " -o " + never + " --env-rotate 30", never, "--env-rotate: needs --env");
  expectCleanFailure("render " + scene + " -o " + never + " --env 1 --env-scale -1", never, "--env-scale");
  expectCleanFailure("render " + scene + " -o " + never + " --env 1 --integrator radiosity", never, "environment light is not supported");
  // A file that is not an image.
  const std::string text = GltfFixture::writeText("not-a-sky.exr", "hello");
  expectCleanFailure("render " + scene + " -o " + never + " --env " + text, never, "not-a-sky.exr");
}

TEST_CASE("cli: --units - info says which units a file's light values were read in, render records an override") {
  GltfFixture f;  // photonlab's marker: radiometric
  const std::string scene = f.write("cli-units.gltf"), dir = GltfFixture::dir();
  Result i = run("info " + scene);
  CHECK_THAT(i.out, Contains("units: radiometric (asset.extras.photonlab.units)"));
  CHECK_THAT(i.out, Contains("point        x1      power [25.1327, 25.1327, 25.1327] W"));  // 4π·2
  Result p = run("info " + scene + " --units photometric");
  CHECK_THAT(p.out, Contains("units: photometric (--units)"));
  CHECK_THAT(p.out, Contains("power [0.0367976, 0.0367976, 0.0367976] W"));  // 4π·2/683
  Result r = run("render " + scene + " -o " + dir + "/units.exr --width 8 --spp 1 --units photometric");
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK_THAT(run("info " + dir + "/units.exr").out, Contains("\"units\": \"photometric\""));
  const std::string never = dir + "/never-units.exr";
  expectCleanFailure("render " + scene + " -o " + never + " --units lumens", never, "--units");
}

TEST_CASE("cli: ordinary mistakes fail before rendering, in one line - a folder or a foreign file as the scene, an output it cannot write, a typing slip") {
  GltfFixture f;
  const std::string scene = f.write("cli-mistakes.gltf"), dir = GltfFixture::dir(), out = dir + "/mistake.png";
  // The scene: a folder, a missing file, files of other formats (named, with what is read).
  expectCleanFailure("render " + dir + " -o " + out, out, "is a folder; photonlab renders a glTF 2.0 file (.gltf or .glb)");
  expectCleanFailure("render " + dir + "/absent.gltf -o " + out, out, "does not exist");
  for (const char* name : {"model.obj", "image.exr", "notes.gltf"}) {
    std::ofstream(dir + "/" + name) << (std::string(name) == "image.exr" ? "v/1\x01 binary" : "# v 0 0 0\nf 1 2 3\n");
    expectCleanFailure("render " + dir + "/" + name + " -o " + out, out, "not a glTF 2.0 file: photonlab reads .gltf (JSON) and .glb");
  }
  CHECK_THAT(run("render " + dir + "/model.obj -o " + out).err, Contains("convert the .obj file to glTF"));
  CHECK_THAT(run("info " + dir + "/notes.gltf").err, Contains("not a glTF 2.0 file"));
  // The output: a folder, or a folder nothing can be written in (/proc, even for root), before
  // the scene is loaded or a pixel rendered.
  expectCleanFailure("render " + scene + " -o " + dir, dir + "/never.png", "is a folder; give a file name ending in .exr or .png");
  Result proc = run("render " + scene + " -o /proc/photonlab-never.png --spp 1 --width 8");
  CHECK(proc.code == 1);
  CHECK_THAT(proc.err, Contains("cannot write in folder /proc"));
  CHECK(proc.err.find("rendering") == std::string::npos);
  // Typing slips get the nearest name.
  expectCleanFailure("render " + scene + " --intergrator path -o " + out, out, "unknown option --intergrator (did you mean --integrator?)");
  expectCleanFailure("rendr " + scene + " -o " + out, out, "unknown command 'rendr' (did you mean render?)");
  expectCleanFailure("render " + scene + " --spp 1 --colour red -o " + out, out, "unknown option --colour");
  CHECK(run("render " + scene + " --spp 1 --colour red -o " + out).err.find("did you mean") == std::string::npos);  // nothing near
  // --exposure and --tonemap with an EXR alone: said, not silently ignored.
  Result exr = run("render " + scene + " --spp 1 --width 8 -q --exposure 2 -o " + dir + "/mistake.exr");
  CHECK(exr.code == 0);
  CHECK_THAT(exr.err, Contains("warning: --exposure applies to PNG output only"));
}

TEST_CASE("cli: camera flags - the view is recorded in the metadata, and mistakes are one line") {
  GltfFixture f;
  const std::string scene = f.write("cli-view.gltf"), dir = GltfFixture::dir(), out = dir + "/view.exr";
  Result r = run("render " + scene + " --spp 1 --width 8 -q --look-from 0,2,5 --look-at 0,0,0 --fov 30 -o " + out);
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK_THAT(run("info " + out).out, Contains("\"view\": \"--look-from 0,2,5 --look-at 0,0,0 --up 0,1,0 --fov 30\""));
  REQUIRE(run("render " + scene + " --spp 1 --width 8 -q --orbit 90,10 -o " + out).code == 0);
  CHECK_THAT(run("info " + out).out, Contains("\"view\": \"--orbit 90,10\""));
  expectCleanFailure("render " + scene + " --look-from 0,2,5 -o " + out, out, "--look-from: needs --look-at");
  expectCleanFailure("render " + scene + " --look-from 0,2 --look-at 0,0,0 -o " + out, out, "--look-from: expected X,Y,Z");
  expectCleanFailure("render " + scene + " --look-from 1,1,1 --look-at 1,1,1 -o " + out, out, "--look-at: must differ from --look-from");
  expectCleanFailure("render " + scene + " --look-from 0,5,0 --look-at 0,0,0 -o " + out, out, "--up: must not point along the view direction");
  expectCleanFailure("render " + scene + " --orbit 0,90 -o " + out, out, "--orbit: the elevation must be strictly between -90 and 90");
  expectCleanFailure("render " + scene + " --orbit 0,10 --camera 0 -o " + out, out, "--camera: not with --orbit");
  expectCleanFailure("render " + scene + " --fov 180 -o " + out, out, "--fov: the vertical field of view must be between 0 and 180");
  expectCleanFailure("render " + scene + " --up 0,0,1 -o " + out, out, "--up: only with --look-from");
}
