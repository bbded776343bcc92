#pragma once
/// @file text_scanner.h
/// Fast, validating reading of whitespace-separated text tables (the
/// Event-Camera Dataset and TUM formats). Files are read in large blocks with
/// fread and lines are handed out as string_views, so memory stays flat
/// whatever the file size. Numbers are parsed with std::from_chars; times in
/// seconds are parsed exactly into integer nanoseconds.

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "evio/core/time.h"

namespace evio::io {

/// Reads a text file line by line through a fixed-size buffer.
class LineReader {
 public:
  /// Opens `path`; throws Error naming the file if it cannot be opened.
  explicit LineReader(std::string path, std::size_t block_bytes = 4u << 20);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  /// Longest line accepted; a longer one is an error naming file and line.
  static constexpr std::size_t kMaxLineBytes = 1u << 20;

  /// Next line without its end-of-line ("\n" or "\r\n"); false at the end.
  /// The view stays valid until the next call.
  bool next(std::string_view& line);

  /// 1-based number of the line last returned.
  std::int64_t lineNumber() const { return line_number_; }
  const std::string& path() const { return path_; }

 private:
  bool refill();
  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<char> buffer_;
  std::size_t begin_ = 0;  // start of unread data in buffer_
  std::size_t end_ = 0;    // end of valid data in buffer_
  bool eof_ = false;
  std::int64_t line_number_ = 0;
};

/// Splits a line into whitespace-separated fields (spaces, tabs, commas are
/// NOT separators). Returns the number of fields written to `out` (at most
/// `max_fields`); `*more` is set when fields remain beyond that.
std::size_t splitFields(std::string_view line, std::string_view* out, std::size_t max_fields,
                        bool* more);

/// True for an empty line, a line of only whitespace, or a '#' comment.
bool isBlankOrComment(std::string_view line);

/// Parses a time in seconds ("12.345678901", "-0.5", "1.5e-3") into integer
/// nanoseconds. Up to 9 fractional digits are exact; further digits round
/// half up. Returns false for anything that is not a finite number or
/// overflows int64 nanoseconds.
bool parseSecondsToNs(std::string_view text, TimeNs* t_ns);

/// Parses a finite double (rejects NaN, inf and trailing characters).
bool parseFiniteDouble(std::string_view text, double* value);

/// Parses a decimal integer (rejects trailing characters and overflow).
bool parseInt64(std::string_view text, std::int64_t* value);

/// Formats integer nanoseconds as seconds with exactly 9 decimals
/// ("-0.000000001", "12.345678901") into `out` (appends).
void appendSeconds(std::string& out, TimeNs t_ns);

/// Appends a double with the shortest representation that reads back exactly.
void appendDouble(std::string& out, double value);

/// Appends a decimal integer.
void appendInt(std::string& out, std::int64_t value);

}  // namespace evio::io
