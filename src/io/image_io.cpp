#include "io/image_io.h"

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <cstdio>
#include <filesystem>

namespace pl {

namespace fs = std::filesystem;

static std::string extensionOf(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(c));
  return ext;
}

void writeImage(const std::string& path, const ImageRGB& image, const std::map<std::string, std::string>& metadata,
                const Display& display) {
  std::string ext = extensionOf(path);
  if (ext != ".exr" && ext != ".png") throw Error(path + ": output must end in .exr or .png");
  fs::path target(path);
  fs::path tmp = target.parent_path() / ("." + target.stem().string() + ".partial-" + std::to_string(getpid()) + ext);
  auto out = OIIO::ImageOutput::create(tmp.string());
  if (!out) throw Error(path + ": cannot create an image writer: " + OIIO::geterror());
  OIIO::ImageSpec spec(image.width, image.height, 3, ext == ".exr" ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  for (auto& [key, value] : metadata) spec.attribute("photonlab:" + key, value);
  if (ext == ".png") {  // how the display values were made
    spec.attribute("photonlab:exposure", formatNumber(display.exposure));
    spec.attribute("photonlab:tonemap", toneCurveName(display.curve));
  }
  if (ext == ".exr") spec.attribute("compression", "zip");
  bool ok = out->open(tmp.string(), spec);
  if (ok) {
    if (ext == ".exr") {
      ok = out->write_image(OIIO::TypeDesc::FLOAT, image.data.data());
    } else {
      std::vector<unsigned char> bytes(image.data.size());
      for (size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = (unsigned char)std::lround(255.0f * displayValue(image.data[i], display));
      ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
    }
    ok = out->close() && ok;
  }
  if (!ok) {
    std::string err = out->geterror();
    std::error_code ec;
    fs::remove(tmp, ec);
    throw Error(path + ": cannot write (" + err + ")");
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(path + ": cannot rename the finished image into place (" + ec.message() + ")");
  }
}

static std::unique_ptr<OIIO::ImageInput> openInput(const std::string& path) {
  if (!fs::exists(path)) throw Error(path + ": no such file");
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(path + ": cannot read image (" + OIIO::geterror() + ")");
  return in;
}

ImageRGB readImage(const std::string& path) {
  auto in = openInput(path);
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels < 1) throw Error(path + ": image has no channels");
  std::vector<float> pixels(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw Error(path + ": cannot read pixels (" + in->geterror() + ")");
  ImageRGB image(spec.width, spec.height);
  for (size_t i = 0; i < size_t(spec.width) * spec.height; ++i)
    for (int c = 0; c < 3; ++c) image.data[i * 3 + c] = pixels[i * spec.nchannels + std::min(c, spec.nchannels - 1)];
  return image;
}

bool isDisplayReferred(const std::string& path) {
  auto in = openInput(path);
  std::string format = in->format_name();
  return format != "openexr" && format != "hdr" && format != "pfm";
}

std::map<std::string, std::string> readImageMetadata(const std::string& path) {
  auto in = openInput(path);
  std::map<std::string, std::string> out;
  for (const auto& p : in->spec().extra_attribs) {
    std::string name = p.name().string();
    if (name.rfind("photonlab:", 0) == 0) out[name.substr(10)] = p.get_string();
  }
  return out;
}

}  // namespace pl
