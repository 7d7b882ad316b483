#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>

#include "io/image_io.h"

using namespace pl;
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
