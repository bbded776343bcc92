#include "evio/core/io/event_labels_bin.h"

#include <array>
#include <cstdio>
#include <cstring>

#include "evio/core/error.h"

namespace evio::io {

namespace {
constexpr char kMagic[8] = {'E', 'V', 'I', 'O', 'L', 'B', 'L', '1'};
constexpr std::size_t kHeaderBytes = 16;

std::array<unsigned char, 8> littleEndian(std::uint64_t v) {
  std::array<unsigned char, 8> b{};
  for (std::size_t i = 0; i < 8; ++i) b[i] = static_cast<unsigned char>((v >> (8 * i)) & 0xFFu);
  return b;
}
}  // namespace

EventLabelWriter::EventLabelWriter(std::string path) : path_(std::move(path)) {
  tmp_path_ = temporaryPathFor(path_);
  file_ = std::fopen(tmp_path_.c_str(), "wb");
  if (!file_) throw Error::inFile(path_, 0, "cannot create the file");
  const std::array<unsigned char, kHeaderBytes> header{};  // rewritten by close()
  if (std::fwrite(header.data(), 1, header.size(), file_) != header.size())
    throw Error::inFile(path_, 0, "write failed");
}

EventLabelWriter::~EventLabelWriter() {
  if (file_) {
    std::fclose(file_);
    std::remove(tmp_path_.c_str());
  }
}

void EventLabelWriter::append(const std::uint8_t* labels, std::size_t count) {
  if (closed_) throw Error::inFile(path_, 0, "append after close");
  for (std::size_t i = 0; i < count; ++i)
    if (labels[i] > kMaxEventLabel)
      throw Error::inFile(path_, 0, "event label " + std::to_string(labels[i]) + " is not 0..3");
  if (count > 0 && std::fwrite(labels, 1, count, file_) != count) throw Error::inFile(path_, 0, "write failed");
  count_ += count;
}

void EventLabelWriter::close() {
  if (closed_) throw Error::inFile(path_, 0, "closed twice");
  const auto n = littleEndian(count_);
  bool ok = std::fseek(file_, 0, SEEK_SET) == 0 && std::fwrite(kMagic, 1, 8, file_) == 8 &&
            std::fwrite(n.data(), 1, 8, file_) == 8;
  ok = std::fclose(file_) == 0 && ok;
  file_ = nullptr;
  closed_ = true;
  if (!ok) {
    std::remove(tmp_path_.c_str());
    throw Error::inFile(path_, 0, "write failed");
  }
  renameFile(tmp_path_, path_);
}

std::vector<std::uint8_t> readEventLabels(const std::string& path) {
  const std::string raw = readFile(path, static_cast<std::size_t>(-1));  // one byte per event: no cap
  if (raw.size() < kHeaderBytes || std::memcmp(raw.data(), kMagic, 8) != 0)
    throw Error::inFile(path, 0, "not an event label file (magic EVIOLBL1 missing)");
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < 8; ++i) n |= static_cast<std::uint64_t>(static_cast<unsigned char>(raw[8 + i])) << (8 * i);
  if (raw.size() - kHeaderBytes != n)
    throw Error::inFile(path, 0, "header says " + std::to_string(n) + " labels, file holds " +
                                     std::to_string(raw.size() - kHeaderBytes));
  std::vector<std::uint8_t> labels(raw.begin() + static_cast<std::ptrdiff_t>(kHeaderBytes), raw.end());
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] > kMaxEventLabel)
      throw Error::inFile(path, 0, "label " + std::to_string(i) + " has value " + std::to_string(labels[i]) +
                                       " (not 0..3)");
  return labels;
}

void writeEventLabels(const std::string& path, const std::vector<std::uint8_t>& labels) {
  EventLabelWriter w(path);
  w.append(labels.data(), labels.size());
  w.close();
}

}  // namespace evio::io
