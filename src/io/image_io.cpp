#include "io/image_io.h"

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <cstdio>
#include <cstring>
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
  Display shown = display;
  if (ext == ".png" && display.autoExposure) shown.exposure = meteredExposure(image.data.data(), image.data.size() / 3);
  if (ext == ".png") {  // how the display values were made
    spec.attribute("photonlab:exposure", formatNumber(shown.exposure));
    if (display.autoExposure) spec.attribute("photonlab:exposure_rule", "auto: the lit pixels' log-average luminance to 0.18");
    spec.attribute("photonlab:tonemap", toneCurveName(shown.curve));
  }
  if (ext == ".exr") spec.attribute("compression", "zip");
  bool ok = out->open(tmp.string(), spec);
  if (ok) {
    if (ext == ".exr") {
      ok = out->write_image(OIIO::TypeDesc::FLOAT, image.data.data());
    } else {
      std::vector<unsigned char> bytes(image.data.size());
      for (size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = (unsigned char)std::lround(255.0f * displayValue(image.data[i], shown));
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

ImageRGB readEnvironmentMap(const std::string& path) {
  ImageRGB image = readImage(path);
  if (isDisplayReferred(path))
    for (float& v : image.data) v = srgbDecode(std::clamp(v, 0.0f, 1.0f));
  return image;
}

bool isDisplayReferred(const std::string& path) {
  auto in = openInput(path);
  std::string format = in->format_name();
  return format != "openexr" && format != "hdr" && format != "pfm";
}

namespace {
// R, G, B, count, then each exact sum's five 64-bit limbs as 32-bit halves: sum.* for
// camera-side samples, splat.* for light-side splats (either or both).
std::vector<std::string> sliceChannelNames(bool sums, bool splats) {
  std::vector<std::string> names = {"R", "G", "B", "count"};
  for (const char* kind : {"sum", "splat"}) {
    if ((std::string(kind) == "sum" && !sums) || (std::string(kind) == "splat" && !splats)) continue;
    for (const char* c : {"R", "G", "B"})
      for (int k = 0; k < ExactSum::kLimbs; ++k)
        for (const char* half : {"lo", "hi"})
          names.push_back(std::string(kind) + "." + c + "." + std::to_string(k) + "." + half);
  }
  return names;
}
}  // namespace

void writeSlice(const std::string& path, const RenderSlice& part, const std::map<std::string, std::string>& metadata) {
  if (extensionOf(path) != ".exr") throw Error(path + ": a slice is written as .exr (its exact sums need the channels)");
  fs::path target(path);
  fs::path tmp = target.parent_path() / ("." + target.stem().string() + ".partial-" + std::to_string(getpid()) + ".exr");
  auto out = OIIO::ImageOutput::create(tmp.string());
  if (!out) throw Error(path + ": cannot create an image writer: " + OIIO::geterror());
  const bool sums = !part.sums.empty(), splats = !part.splats.empty();
  const std::vector<std::string> names = sliceChannelNames(sums, splats);
  const int channels = int(names.size());
  OIIO::ImageSpec spec(part.width, part.height, channels, OIIO::TypeDesc::UINT);
  spec.channelnames = names;
  spec.channelformats.assign(size_t(channels), OIIO::TypeDesc::UINT);
  for (int c = 0; c < 3; ++c) spec.channelformats[size_t(c)] = OIIO::TypeDesc::FLOAT;
  spec.alpha_channel = -1;
  for (auto& [key, value] : metadata) spec.attribute("photonlab:" + key, value);
  spec.attribute("photonlab:range_begin", std::to_string(part.begin));
  spec.attribute("photonlab:range_end", std::to_string(part.end));
  spec.attribute("photonlab:range_step", std::to_string(part.step));
  spec.attribute("compression", "zip");
  // Every channel is 4 bytes: one uint32 buffer, the float channels' bits copied in.
  const size_t pixels = size_t(part.width) * part.height;
  std::vector<uint32_t> data(pixels * size_t(channels));
  const ImageRGB mean = part.mean();
  for (size_t i = 0; i < pixels; ++i) {
    uint32_t* d = &data[i * size_t(channels)];
    std::memcpy(d, &mean.data[i * 3], 3 * sizeof(float));
    d[3] = part.counts[i];
    size_t at = 4;
    for (const std::vector<ExactSum>* v : {&part.sums, &part.splats}) {
      if (v->empty()) continue;
      for (int c = 0; c < 3; ++c) {
        const uint64_t* limbs = (*v)[i * 3 + size_t(c)].limbs();
        for (int k = 0; k < ExactSum::kLimbs; ++k) d[at++] = uint32_t(limbs[k]), d[at++] = uint32_t(limbs[k] >> 32);
      }
    }
  }
  bool ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::UNKNOWN, data.data());
  ok = out->close() && ok;
  std::error_code ec;
  if (!ok) {
    std::string err = out->geterror();
    fs::remove(tmp, ec);
    throw Error(path + ": cannot write (" + err + ")");
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(path + ": cannot rename the finished image into place (" + ec.message() + ")");
  }
}

RenderSlice readSlice(const std::string& path) {
  auto in = openInput(path);
  const OIIO::ImageSpec& spec = in->spec();
  auto has = [&](const std::string& name) {
    for (int c = 0; c < spec.nchannels; ++c)
      if (spec.channel_name(c) == name) return true;
    return false;
  };
  const bool sums = has("sum.R.0.lo"), splats = has("splat.R.0.lo");
  // OpenEXR stores channels sorted by name: find each by its name.
  const std::vector<std::string> names = sliceChannelNames(sums, splats);
  std::vector<int> at(names.size(), -1);
  for (size_t i = 0; i < names.size(); ++i)
    for (int c = 0; c < spec.nchannels; ++c)
      if (spec.channel_name(c) == names[i]) at[i] = c;
  bool ok = (sums || splats) && spec.nchannels == int(names.size());
  for (size_t i = 0; i < names.size() && ok; ++i)
    ok = at[i] >= 0 && spec.channelformat(at[i]).size() == 4 && (i < 3 || spec.channelformat(at[i]) == OIIO::TypeDesc::UINT);
  if (!ok) throw Error(path + ": not a render slice (photonlab render --sample-range or --pass-range writes them)");
  RenderSlice part;
  part.width = spec.width, part.height = spec.height;
  try {
    part.begin = std::stoi(spec.get_string_attribute("photonlab:range_begin"));
    part.end = std::stoi(spec.get_string_attribute("photonlab:range_end"));
    part.step = std::stoi(spec.get_string_attribute("photonlab:range_step", "1"));
  } catch (const std::exception&) {
    throw Error(path + ": a render slice without its range (range_begin, range_end)");
  }
  const size_t pixels = size_t(part.width) * part.height, channels = names.size();
  std::vector<uint32_t> data(pixels * channels);
  // Native formats (floats and uints, 4 bytes each), as written.
  if (!in->read_image(0, 0, 0, int(channels), OIIO::TypeDesc::UNKNOWN, data.data()))
    throw Error(path + ": cannot read pixels (" + in->geterror() + ")");
  if (sums) part.sums.resize(pixels * 3);
  if (splats) part.splats.resize(pixels * 3);
  part.counts.resize(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    const uint32_t* d = &data[i * channels];
    part.counts[i] = d[at[3]];
    size_t next = 4;
    for (std::vector<ExactSum>* v : {&part.sums, &part.splats}) {
      if (v->empty()) continue;
      for (int c = 0; c < 3; ++c) {
        uint64_t limbs[ExactSum::kLimbs];
        for (int k = 0; k < ExactSum::kLimbs; ++k, next += 2)
          limbs[k] = uint64_t(d[at[next]]) | uint64_t(d[at[next + 1]]) << 32;
        (*v)[i * 3 + size_t(c)].setLimbs(limbs);
      }
    }
  }
  return part;
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
