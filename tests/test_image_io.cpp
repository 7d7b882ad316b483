#include <catch2/catch.hpp>

#include "cli_helpers.h"

#include <unistd.h>

#include <filesystem>
#include <set>

#include "experiment/experiment.h"
#include "integrators/registry.h"
#include "io/image_io.h"

using namespace pl;
using namespace pl::test;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

TEST_CASE("EXR round trip keeps float values and metadata  PNG is sRGB-encoded") {
  fs::path dir = fs::temp_directory_path() / ("photonlab-io-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  ImageRGB img(3, 2);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = 0.1f * i + 1e-3f;
  img.data[5] = 12.5f;  // HDR values survive in EXR
  writeImage((dir / "a.exr").string(), img, {{"integrator", "path"}, {"spp", "16"}});
  ImageRGB back = readImage((dir / "a.exr").string());
  REQUIRE(back.width == 3);
  REQUIRE(back.height == 2);
  CHECK(back.data == img.data);
  auto meta = readImageMetadata((dir / "a.exr").string());
  CHECK(meta["integrator"] == "path");
  CHECK(meta["spp"] == "16");

  ImageRGB grey(1, 1);
  grey.data = {0.5f, 0.0f, 2.0f};
  writeImage((dir / "g.png").string(), grey);
  ImageRGB png = readImage((dir / "g.png").string());
  CHECK(png.data[0] == Approx(188.0f / 255.0f));  // sRGB(0.5) = 0.7354 → 188
  CHECK(png.data[1] == 0.0f);
  CHECK(png.data[2] == 1.0f);  // clamped
  // No temporary files left behind.
  for (auto& e : fs::directory_iterator(dir)) CHECK(e.path().filename().string().find(".partial-") == std::string::npos);
  CHECK_THROWS_AS(writeImage((dir / "x.tiff").string(), grey), Error);
  CHECK_THROWS_AS(writeImage((dir / "missing" / "x.exr").string(), grey), Error);
  CHECK_FALSE(fs::exists(dir / "missing"));
  fs::remove_all(dir);
}

TEST_CASE("PNG exposure and tone curves - EXR untouched - the PNG records how it was made") {
  fs::path dir = fs::temp_directory_path() / ("photonlab-io-tm-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  ImageRGB img(4, 1);
  img.data = {0.25f, 0.5f, 1.0f, 2.0f, 4.0f, 8.0f, 0.0f, 0.1f, 100.0f, 0.5f, 0.5f, 0.5f};
  // +1 EV is the image times 2.
  ImageRGB doubled = img;
  for (float& v : doubled.data) v *= 2;
  writeImage((dir / "e.png").string(), img, {}, Display{1.0, ToneCurve::Clamp});
  writeImage((dir / "d.png").string(), doubled);
  CHECK(readImage((dir / "e.png").string()).data == readImage((dir / "d.png").string()).data);
  // ACES (Narkowicz's fit): f(x) = x(2.51x + 0.03)/(x(2.43x + 0.59) + 0.14), then sRGB.
  writeImage((dir / "a.png").string(), img, {}, Display{0.0, ToneCurve::ACES});
  ImageRGB aces = readImage((dir / "a.png").string());
  auto f = [](double x) { return x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14); };
  auto srgb = [](double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; };
  for (size_t i = 0; i < img.data.size(); ++i) {
    double expected = std::round(255 * srgb(std::min(1.0, f(img.data[i])))) / 255;
    CHECK(aces.data[i] == Approx(expected).margin(1e-6));
  }
  // Highlights roll off instead of clipping: 1, 2, 4 stay apart; only far above 7 is white.
  CHECK(aces.data[2] < aces.data[3]);
  CHECK(aces.data[3] < aces.data[4]);
  CHECK(aces.data[4] < 1.0f);
  CHECK(aces.data[8] == 1.0f);
  CHECK(displayValue(1.0f, Display{0.0, ToneCurve::ACES}) == Approx(srgbTransfer(0.8038f)).epsilon(1e-3));
  auto meta = readImageMetadata((dir / "a.png").string());
  CHECK(meta["tonemap"] == "aces");
  CHECK(meta["exposure"] == "0");
  // EXR ignores the display settings.
  writeImage((dir / "a.exr").string(), img, {}, Display{3.0, ToneCurve::ACES});
  CHECK(readImage((dir / "a.exr").string()).data == img.data);
  CHECK(isDisplayReferred((dir / "a.png").string()));
  CHECK_FALSE(isDisplayReferred((dir / "a.exr").string()));
  fs::remove_all(dir);
}

TEST_CASE("image metadata: every key a render writes is documented (photonlab reference metadata)") {
  // Every integrator, with every optional field of the run set, so that every branch of
  // runMetadata() writes its key; each must be a declared parameter or in metadataKeys().
  std::set<std::string> documented;
  for (const pl::MetadataKey& k : pl::metadataKeys()) {
    CHECK(!k.doc.empty());
    CHECK(documented.insert(k.key).second);  // listed once
  }
  for (const pl::IntegratorEntry* e : pl::integrators()) {
    pl::RunSettings s = pl::RunSettings::of(e->name);
    s.image.width = s.image.height = 8;
    s.image.camera = 0;
    s.image.environment.enabled = true;
    s.image.units = "radiometric";
    s.image.spectral = true;
    s.image.timeLimit = 2;
    s.image.nanAov = true;
    pl::CheckpointInfo info;
    info.spp = info.passes = 3;
    info.meanWork = 3.5;
    info.photons = 100;
    info.meanRadius = 0.01;
    info.timeUp = info.interrupted = true;
    for (auto& [key, value] : pl::runMetadata(s, info, "scene.gltf")) {
      INFO(e->name << ": metadata key " << key);
      bool parameter = false;
      for (const pl::ParamSpec& p : e->params) parameter = parameter || p.metaKey() == key;
      CHECK((parameter || documented.count(key)));
    }
  }
}

TEST_CASE("cli: automatic exposure puts the lit pixels' log-average luminance at middle grey - tonemap develops an EXR again") {
  const std::string dir = GltfFixture::dir();
  auto refused = [&](const std::string& args, const std::string& output, const std::string& mentions) {
    Result r = run(args);
    INFO(args << "\n" << r.err);
    CHECK(r.code == 1);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_THAT(r.err, Contains(mentions));
    CHECK_FALSE(fs::exists(output));
  };
  // An image of known luminance: half the pixels 0.5 (grey), half black. The black ones are not
  // metered; the grey ones go to 0.18, EV = log2(0.36), shown as sRGB(0.18) = 118/255.
  ImageRGB grey(8, 4);
  for (size_t i = 0; i < grey.data.size(); ++i) grey.data[i] = (i / 3) % 2 ? 0.5f : 0.0f;
  CHECK(meteredExposure(grey.data.data(), 32) == Approx(std::log2(0.36)).epsilon(1e-12));
  writeImage(dir + "/known.exr", grey, {{"integrator", "path"}});
  Result r = run("tonemap " + dir + "/known.exr -o " + dir + "/known.png");
  INFO(r.err);
  REQUIRE(r.code == 0);
  const ImageRGB png = readImage(dir + "/known.png");  // decoded: 118/255
  CHECK(png.data[3] == Approx(std::round(255 * srgbTransfer(0.18f)) / 255).margin(1e-6));
  CHECK(png.data[0] == 0.0f);
  auto meta = readImageMetadata(dir + "/known.png");
  CHECK(std::stod(meta["exposure"]) == Approx(std::log2(0.36)).epsilon(1e-6));
  CHECK_THAT(meta["exposure_rule"], Contains("log-average"));
  CHECK(meta["integrator"] == "path");  // the EXR's metadata kept
  // Two values a and b, equally many: the log-average is √(ab).
  ImageRGB two(2, 1);
  two.data = {0.02f, 0.02f, 0.02f, 2.0f, 2.0f, 2.0f};
  CHECK(meteredExposure(two.data.data(), 2) == Approx(std::log2(0.18 / std::sqrt(0.04))).epsilon(1e-6));
  ImageRGB black(2, 2);
  CHECK(meteredExposure(black.data.data(), 4) == 0.0);  // nothing lit: unchanged
  // A fixed exposure and curve; the mistakes.
  REQUIRE(run("tonemap " + dir + "/known.exr -o " + dir + "/fixed.png --exposure -1 --tonemap aces").code == 0);
  CHECK(readImageMetadata(dir + "/fixed.png")["exposure"] == "-1");
  refused("tonemap " + dir + "/known.exr -o " + dir + "/bad.png --exposure bright", dir + "/bad.png", "--exposure: must be auto or a number");
  refused("tonemap " + dir + "/known.png -o " + dir + "/bad.png", dir + "/bad.png", "tonemap develops a linear image (.exr)");
  refused("tonemap " + dir + "/known.exr -o " + dir + "/bad.exr", dir + "/bad.exr", "tonemap writes a .png");
}

