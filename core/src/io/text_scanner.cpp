#include "evio/core/io/text_scanner.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "evio/core/error.h"

namespace evio::io {

LineReader::LineReader(std::string path, std::size_t block_bytes) : path_(std::move(path)) {
  file_ = std::fopen(path_.c_str(), "rb");
  if (!file_) throw Error::inFile(path_, 0, std::string("cannot open file: ") + std::strerror(errno));
  // A small file gets a small buffer; a long line still grows it (refill).
  struct stat st {};
  std::size_t size = block_bytes;
  if (::fstat(::fileno(file_), &st) == 0 && st.st_size >= 0)
    size = std::min(block_bytes, static_cast<std::size_t>(st.st_size) + 1);
  buffer_.resize(std::max<std::size_t>(size, 256));
}

LineReader::~LineReader() {
  if (file_) std::fclose(file_);
}

bool LineReader::refill() {
  if (eof_) return false;
  // Move the unread tail to the front; grow if one line fills the buffer.
  const std::size_t tail = end_ - begin_;
  if (tail > 0 && begin_ > 0) std::memmove(buffer_.data(), buffer_.data() + begin_, tail);
  begin_ = 0;
  end_ = tail;
  if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);
  const std::size_t got = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
  if (got == 0) {
    if (std::ferror(file_)) throw Error::inFile(path_, line_number_ + 1, "read error");
    eof_ = true;
    return false;
  }
  end_ += got;
  return true;
}

bool LineReader::next(std::string_view& line) {
  for (;;) {
    const char* start = buffer_.data() + begin_;
    const auto* nl = static_cast<const char*>(std::memchr(start, '\n', end_ - begin_));
    if (nl) {
      std::size_t len = static_cast<std::size_t>(nl - start);
      begin_ += len + 1;
      if (len > 0 && start[len - 1] == '\r') --len;
      line = std::string_view(start, len);
      ++line_number_;
      return true;
    }
    if (end_ - begin_ > kMaxLineBytes)
      throw Error::inFile(path_, line_number_ + 1,
                          "line longer than " + std::to_string(kMaxLineBytes) + " bytes (not a text table?)");
    if (!refill()) {
      if (begin_ == end_) return false;
      // Last line without a newline.
      std::size_t len = end_ - begin_;
      const char* s = buffer_.data() + begin_;
      begin_ = end_;
      if (len > 0 && s[len - 1] == '\r') --len;
      line = std::string_view(s, len);
      ++line_number_;
      return true;
    }
  }
}

namespace {
inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

std::size_t splitFields(std::string_view line, std::string_view* out, std::size_t max_fields,
                        bool* more) {
  std::size_t n = 0;
  std::size_t i = 0;
  const std::size_t size = line.size();
  *more = false;
  while (true) {
    while (i < size && isSpace(line[i])) ++i;
    if (i >= size) break;
    const std::size_t start = i;
    while (i < size && !isSpace(line[i])) ++i;
    if (n == max_fields) {
      *more = true;
      break;
    }
    out[n++] = line.substr(start, i - start);
  }
  return n;
}

bool isBlankOrComment(std::string_view line) {
  for (const char c : line) {
    if (c == '#') return true;
    if (!isSpace(c)) return false;
  }
  return true;
}

bool parseFiniteDouble(std::string_view text, double* value) {
  if (text.empty()) return false;
  const char* first = text.data();
  const char* last = first + text.size();
  if (*first == '+') ++first;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, *value);
  return ec == std::errc() && ptr == last && std::isfinite(*value);
}

bool parseInt64(std::string_view text, std::int64_t* value) {
  if (text.empty()) return false;
  const char* first = text.data();
  const char* last = first + text.size();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, *value);
  return ec == std::errc() && ptr == last;
}

bool parseSecondsToNs(std::string_view text, TimeNs* t_ns) {
  const char* p = text.data();
  const char* end = p + text.size();
  if (p == end) return false;
  bool negative = false;
  if (*p == '-' || *p == '+') {
    negative = *p == '-';
    ++p;
  }
  // Integer part.
  std::int64_t seconds = 0;
  const char* int_start = p;
  while (p < end && *p >= '0' && *p <= '9') {
    if (seconds > (std::numeric_limits<std::int64_t>::max() / kNsPerSecond) / 10) return false;
    seconds = seconds * 10 + (*p - '0');
    ++p;
  }
  bool any_digit = p > int_start;
  std::int64_t frac_ns = 0;
  if (p < end && *p == '.') {
    ++p;
    int digits = 0;
    bool round_up = false;
    const char* frac_start = p;
    while (p < end && *p >= '0' && *p <= '9') {
      if (digits < 9) {
        frac_ns = frac_ns * 10 + (*p - '0');
      } else if (digits == 9) {
        round_up = *p >= '5';
      }
      ++digits;
      ++p;
    }
    any_digit = any_digit || p > frac_start;
    for (int d = digits; d < 9; ++d) frac_ns *= 10;
    if (round_up) ++frac_ns;
  }
  if (!any_digit) return false;
  if (p != end) {
    // Exponent or other syntax: fall back to a double (ns rounding).
    if (*p != 'e' && *p != 'E') return false;
    double v = 0.0;
    if (!parseFiniteDouble(text, &v)) return false;
    const double ns = v * 1e9;
    if (!(std::fabs(ns) < 9.2e18)) return false;
    *t_ns = static_cast<TimeNs>(std::llround(ns));
    return true;
  }
  // seconds * 1e9 + frac_ns must fit int64 (|t| < 9.223372036e9 s).
  if (seconds > std::numeric_limits<std::int64_t>::max() / kNsPerSecond) return false;
  if (frac_ns > std::numeric_limits<std::int64_t>::max() - seconds * kNsPerSecond) return false;
  const TimeNs total = seconds * kNsPerSecond + frac_ns;
  *t_ns = negative ? -total : total;
  return true;
}

void appendInt(std::string& out, std::int64_t value) {
  char buf[24];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), value);
  out.append(buf, ptr);
}

void appendSeconds(std::string& out, TimeNs t_ns) {
  if (t_ns < 0) {
    out.push_back('-');
    // -(INT64_MIN) overflows; such times are rejected by the readers anyway.
    t_ns = t_ns == std::numeric_limits<TimeNs>::min() ? std::numeric_limits<TimeNs>::max() : -t_ns;
  }
  appendInt(out, t_ns / kNsPerSecond);
  char frac[10];
  std::int64_t f = t_ns % kNsPerSecond;
  frac[0] = '.';
  for (int i = 9; i >= 1; --i) {
    frac[i] = static_cast<char>('0' + f % 10);
    f /= 10;
  }
  out.append(frac, 10);
}

void appendDouble(std::string& out, double value) {
  char buf[32];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), value);  // shortest round-trip
  out.append(buf, ptr);
}

}  // namespace evio::io
