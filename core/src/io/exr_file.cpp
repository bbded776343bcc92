#include "evio/core/io/exr_file.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <cstdio>
#include <exception>
#include <set>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"

namespace evio::io {

void writeExr(const std::string& path, const std::vector<ExrChannel>& channels) {
  if (channels.empty()) throw Error::inFile(path, 0, "EXR: no channels to write");
  const cv::Size size = channels.front().second.size();
  std::set<std::string> names;
  for (const auto& [name, image] : channels) {
    if (name.empty() || !names.insert(name).second)
      throw Error::inFile(path, 0, "EXR: channel names must be unique and non-empty ('" + name + "')");
    if (image.type() != CV_32FC1 || image.size() != size || image.empty())
      throw Error::inFile(path, 0, "EXR: channel '" + name + "' must be a non-empty CV_32FC1 of " +
                                       std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  // Continuous copies so that the frame buffer strides are simple.
  std::vector<cv::Mat> data;
  for (const auto& c : channels) data.push_back(c.second.isContinuous() ? c.second : c.second.clone());

  const std::string tmp = temporaryPathFor(path);
  try {
    Imf::Header header(size.width, size.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::FrameBuffer fb;
    for (std::size_t i = 0; i < channels.size(); ++i) {
      header.channels().insert(channels[i].first, Imf::Channel(Imf::FLOAT));
      fb.insert(channels[i].first,
                Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(data[i].ptr<float>()), sizeof(float),
                           sizeof(float) * static_cast<std::size_t>(size.width)));
    }
    {
      Imf::OutputFile file(tmp.c_str(), header, 1);
      file.setFrameBuffer(fb);
      file.writePixels(size.height);
    }
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    throw Error::inFile(path, 0, std::string("EXR write failed: ") + e.what());
  }
  renameFile(tmp, path);
}

std::vector<ExrChannel> readExr(const std::string& path) {
  std::vector<ExrChannel> out;
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw Error::inFile(path, 0, "cannot open file (missing or unreadable)");
    std::fclose(f);
  }
  try {
    Imf::InputFile file(path.c_str(), 1);
    const Imath::Box2i dw = file.header().dataWindow();
    const int width = dw.max.x - dw.min.x + 1;
    const int height = dw.max.y - dw.min.y + 1;
    if (width <= 0 || height <= 0) throw Error::inFile(path, 0, "EXR has an empty data window");
    Imf::FrameBuffer fb;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
        throw Error::inFile(path, 0, std::string("EXR channel '") + it.name() + "' is subsampled");
      cv::Mat image(height, width, CV_32FC1);
      // Slices are addressed from the data window origin (may be non-zero).
      char* base = reinterpret_cast<char*>(image.ptr<float>()) -
                   (static_cast<std::ptrdiff_t>(dw.min.x) +
                    static_cast<std::ptrdiff_t>(dw.min.y) * width) *
                       static_cast<std::ptrdiff_t>(sizeof(float));
      fb.insert(it.name(), Imf::Slice(Imf::FLOAT, base, sizeof(float),
                                      sizeof(float) * static_cast<std::size_t>(width)));
      out.emplace_back(it.name(), image);
    }
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error::inFile(path, 0, std::string("not a readable EXR file: ") + e.what());
  }
  if (out.empty()) throw Error::inFile(path, 0, "EXR file has no channels");
  return out;
}

cv::Mat readExrChannel(const std::string& path, const std::string& name) {
  const auto channels = readExr(path);
  const auto find = [&](const std::string& n) -> const cv::Mat* {
    for (const auto& c : channels)
      if (c.first == n) return &c.second;
    return nullptr;
  };
  if (!name.empty()) {
    if (const auto* m = find(name)) return *m;
    std::string known;
    for (const auto& c : channels) known += (known.empty() ? "" : ", ") + c.first;
    throw Error::inFile(path, 0, "EXR has no channel '" + name + "' (channels: " + known + ")");
  }
  for (const char* n : {"Y", "R", "Z", "depth", "height"})
    if (const auto* m = find(n)) return *m;
  if (channels.size() == 1) return channels.front().second;
  throw Error::inFile(path, 0, "EXR has several channels and none is Y, R, Z, depth or height");
}

}  // namespace evio::io
