#include "evio/core/io/mesh_file.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <string_view>
#include <tuple>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"

namespace evio::io {

namespace {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

/// Splits on blanks.
std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

bool parseDouble(std::string_view s, double* v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(*v);
}

bool parseInt(std::string_view s, long long* v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

void checkNonEmpty(const std::string& path, const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) throw Error::inFile(path, 0, "mesh has no triangles");
}

// --- OBJ ------------------------------------------------------------------

TriangleMesh parseObj(const std::string& path, const std::string& text) {
  std::vector<Eigen::Vector3f> v, vn;
  std::vector<Eigen::Vector2f> vt;
  using Corner = std::tuple<int, int, int>;  // position, uv, normal (-1 = none)
  std::map<Corner, int> corner_index;
  std::vector<Corner> corners;
  std::vector<Eigen::Vector3i> triangles;
  bool any_uv = false, any_normal = false;

  std::size_t pos = 0;
  std::int64_t line_no = 0;
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto tok = tokens(line);
    if (tok.empty()) continue;
    const auto fail = [&](const std::string& what) -> void {
      throw Error::inFile(path, line_no, what);
    };
    const auto readNumbers = [&](std::size_t n, double* out) {
      if (tok.size() < n + 1) fail("'" + std::string(tok[0]) + "' needs " + std::to_string(n) + " numbers");
      for (std::size_t i = 0; i < n; ++i)
        if (!parseDouble(tok[i + 1], &out[i]))
          fail("malformed number '" + std::string(tok[i + 1]) + "'");
    };
    if (tok[0] == "v") {
      double x[3];
      readNumbers(3, x);
      v.emplace_back(static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2]));
    } else if (tok[0] == "vt") {
      double x[2];
      readNumbers(2, x);
      vt.emplace_back(static_cast<float>(x[0]), static_cast<float>(x[1]));
    } else if (tok[0] == "vn") {
      double x[3];
      readNumbers(3, x);
      Eigen::Vector3f n(static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2]));
      if (!(n.norm() > 0.0f)) fail("zero normal");
      vn.push_back(n.normalized());
    } else if (tok[0] == "f") {
      if (tok.size() < 4) fail("a face needs at least 3 corners");
      std::vector<int> face;
      for (std::size_t i = 1; i < tok.size(); ++i) {
        // Split "p/t/n" into up to three fields.
        std::array<std::string_view, 3> f{};
        std::string_view rest = tok[i];
        for (int k = 0; k < 3; ++k) {
          const auto slash = rest.find('/');
          f[static_cast<std::size_t>(k)] = rest.substr(0, slash);
          if (slash == std::string_view::npos) {
            rest = {};
            break;
          }
          rest = rest.substr(slash + 1);
          if (k == 2) fail("malformed face corner '" + std::string(tok[i]) + "'");
        }
        const auto resolve = [&](std::string_view s, std::size_t count, const char* what) -> int {
          if (s.empty()) return -1;
          long long idx = 0;
          if (!parseInt(s, &idx) || idx == 0)
            fail("malformed " + std::string(what) + " index '" + std::string(s) + "'");
          const long long n = static_cast<long long>(count);
          const long long zero_based = idx > 0 ? idx - 1 : n + idx;
          if (zero_based < 0 || zero_based >= n)
            fail(std::string(what) + " index " + std::to_string(idx) + " out of range (" +
                 std::to_string(n) + " defined so far)");
          return static_cast<int>(zero_based);
        };
        if (f[0].empty()) fail("face corner without a vertex index");
        const Corner c{resolve(f[0], v.size(), "vertex"), resolve(f[1], vt.size(), "texture"),
                       resolve(f[2], vn.size(), "normal")};
        any_uv |= std::get<1>(c) >= 0;
        any_normal |= std::get<2>(c) >= 0;
        auto [it, inserted] = corner_index.emplace(c, static_cast<int>(corners.size()));
        if (inserted) corners.push_back(c);
        face.push_back(it->second);
      }
      for (std::size_t i = 1; i + 1 < face.size(); ++i)
        triangles.emplace_back(face[0], face[i], face[i + 1]);
    }
    // Any other statement is ignored.
  }

  TriangleMesh mesh;
  mesh.triangles = std::move(triangles);
  mesh.positions.reserve(corners.size());
  for (const auto& [p, t, n] : corners) {
    mesh.positions.push_back(v[static_cast<std::size_t>(p)]);
    if (any_uv) mesh.uvs.push_back(t >= 0 ? vt[static_cast<std::size_t>(t)] : Eigen::Vector2f::Zero());
    if (any_normal)
      mesh.normals.push_back(n >= 0 ? vn[static_cast<std::size_t>(n)] : Eigen::Vector3f::Zero());
  }
  // Corners without a normal in a file that has some: drop normals altogether.
  if (any_normal)
    for (const auto& n : mesh.normals)
      if (n.isZero()) {
        mesh.normals.clear();
        break;
      }
  checkNonEmpty(path, mesh);
  return mesh;
}

// --- PLY ------------------------------------------------------------------

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool plyType(std::string_view s, PlyType* t) {
  static constexpr std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [name, type] : kNames)
    if (s == name) {
      *t = type;
      return true;
    }
  return false;
}

std::size_t plySize(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8: return 1;
    case PlyType::kInt16:
    case PlyType::kUint16: return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32: return 4;
    case PlyType::kFloat64: return 8;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

/// Reads values of the PLY body one at a time, in ASCII or binary.
class PlyReader {
 public:
  PlyReader(const std::string& path, const std::string& text, std::size_t pos, int format)
      : path_(path), text_(text), pos_(pos), format_(format) {}

  double next(PlyType t, const std::string& where) {
    if (format_ == 0) return nextAscii(where);
    const std::size_t n = plySize(t);
    if (pos_ + n > text_.size()) throw Error::inFile(path_, 0, where + ": file is truncated");
    unsigned char b[8];
    std::memcpy(b, text_.data() + pos_, n);
    pos_ += n;
    const bool swap = (format_ == 2) == (std::endian::native == std::endian::little);
    if (swap) std::reverse(b, b + n);
    switch (t) {
      case PlyType::kInt8: return static_cast<double>(static_cast<std::int8_t>(b[0]));
      case PlyType::kUint8: return static_cast<double>(b[0]);
      case PlyType::kInt16: return load<std::int16_t>(b);
      case PlyType::kUint16: return load<std::uint16_t>(b);
      case PlyType::kInt32: return load<std::int32_t>(b);
      case PlyType::kUint32: return load<std::uint32_t>(b);
      case PlyType::kFloat32: return static_cast<double>(load<float>(b));
      case PlyType::kFloat64: return load<double>(b);
    }
    return 0.0;
  }

 private:
  template <class T>
  static double load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return static_cast<double>(v);
  }

  double nextAscii(const std::string& where) {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    if (pos_ == start) throw Error::inFile(path_, 0, where + ": file is truncated");
    double v = 0.0;
    if (!parseDouble(std::string_view(text_).substr(start, pos_ - start), &v))
      throw Error::inFile(path_, 0,
                          where + ": malformed number '" + text_.substr(start, pos_ - start) + "'");
    return v;
  }

  const std::string& path_;
  const std::string& text_;
  std::size_t pos_;
  int format_;  // 0 ascii, 1 little endian, 2 big endian
};

TriangleMesh parsePly(const std::string& path, const std::string& text) {
  std::size_t pos = 0;
  std::int64_t line_no = 0;
  int format = -1;
  std::vector<PlyElement> elements;
  const auto nextLine = [&]() -> std::string_view {
    if (pos >= text.size()) throw Error::inFile(path, line_no, "PLY header has no end_header");
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    return trim(line);
  };
  if (nextLine() != "ply") throw Error::inFile(path, 1, "not a PLY file (first line must be 'ply')");
  for (;;) {
    const auto tok = tokens(nextLine());
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") break;
    if (tok[0] == "format") {
      if (tok.size() != 3) throw Error::inFile(path, line_no, "malformed format line");
      if (tok[1] == "ascii") format = 0;
      else if (tok[1] == "binary_little_endian") format = 1;
      else if (tok[1] == "binary_big_endian") format = 2;
      else throw Error::inFile(path, line_no, "unknown PLY format '" + std::string(tok[1]) + "'");
    } else if (tok[0] == "element") {
      long long count = 0;
      if (tok.size() != 3 || !parseInt(tok[2], &count) || count < 0)
        throw Error::inFile(path, line_no, "malformed element line");
      elements.push_back({std::string(tok[1]), static_cast<std::size_t>(count), {}});
    } else if (tok[0] == "property") {
      if (elements.empty()) throw Error::inFile(path, line_no, "property before any element");
      PlyProperty p;
      bool ok = false;
      if (tok.size() == 5 && tok[1] == "list") {
        p.is_list = true;
        ok = plyType(tok[2], &p.count_type) && plyType(tok[3], &p.type);
        p.name = std::string(tok[4]);
      } else if (tok.size() == 3) {
        ok = plyType(tok[1], &p.type);
        p.name = std::string(tok[2]);
      }
      if (!ok) throw Error::inFile(path, line_no, "malformed property line");
      elements.back().properties.push_back(p);
    } else {
      throw Error::inFile(path, line_no, "unknown PLY header line '" + std::string(tok[0]) + "'");
    }
  }
  if (format < 0) throw Error::inFile(path, line_no, "PLY header has no format line");

  TriangleMesh mesh;
  PlyReader reader(path, text, pos, format);
  for (const auto& element : elements) {
    const bool is_vertex = element.name == "vertex";
    const bool is_face = element.name == "face";
    int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, iu = -1, iv = -1, iface = -1;
    for (int k = 0; k < static_cast<int>(element.properties.size()); ++k) {
      const auto& n = element.properties[static_cast<std::size_t>(k)].name;
      if (n == "x") ix = k;
      if (n == "y") iy = k;
      if (n == "z") iz = k;
      if (n == "nx") inx = k;
      if (n == "ny") iny = k;
      if (n == "nz") inz = k;
      if (n == "u" || n == "s" || n == "texture_u") iu = k;
      if (n == "v" || n == "t" || n == "texture_v") iv = k;
      if (n == "vertex_indices" || n == "vertex_index") iface = k;
    }
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0))
      throw Error::inFile(path, 0, "PLY vertex element lacks x, y or z");
    if (is_face && iface < 0) throw Error::inFile(path, 0, "PLY face element lacks vertex_indices");
    const bool has_n = is_vertex && inx >= 0 && iny >= 0 && inz >= 0;
    const bool has_uv = is_vertex && iu >= 0 && iv >= 0;
    std::vector<double> values(element.properties.size());
    std::vector<long long> face;
    for (std::size_t e = 0; e < element.count; ++e) {
      const std::string where = element.name + "[" + std::to_string(e) + "]";
      for (std::size_t k = 0; k < element.properties.size(); ++k) {
        const auto& p = element.properties[k];
        if (!p.is_list) {
          values[k] = reader.next(p.type, where);
          continue;
        }
        const double count = reader.next(p.count_type, where);
        if (count < 0 || count > 1e6 || count != std::floor(count))
          throw Error::inFile(path, 0, where + ": bad list length");
        const bool keep = is_face && static_cast<int>(k) == iface;
        if (keep) face.clear();
        for (int i = 0; i < static_cast<int>(count); ++i) {
          const double x = reader.next(p.type, where);
          if (keep) face.push_back(static_cast<long long>(x));
        }
      }
      if (is_vertex) {
        const auto at = [&](int k) { return static_cast<float>(values[static_cast<std::size_t>(k)]); };
        const Eigen::Vector3f p(at(ix), at(iy), at(iz));
        if (!p.allFinite()) throw Error::inFile(path, 0, where + ": non-finite position");
        mesh.positions.push_back(p);
        if (has_n) {
          Eigen::Vector3f n(at(inx), at(iny), at(inz));
          mesh.normals.push_back(n.norm() > 0.0f ? n.normalized() : n);
        }
        if (has_uv) mesh.uvs.emplace_back(at(iu), at(iv));
      } else if (is_face) {
        if (face.size() < 3) throw Error::inFile(path, 0, where + ": a face needs 3 vertices");
        for (const long long i : face)
          if (i < 0 || i >= static_cast<long long>(mesh.positions.size()))
            throw Error::inFile(path, 0, where + ": vertex index " + std::to_string(i) +
                                             " out of range");
        for (std::size_t i = 1; i + 1 < face.size(); ++i)
          mesh.triangles.emplace_back(static_cast<int>(face[0]), static_cast<int>(face[i]),
                                      static_cast<int>(face[i + 1]));
      }
    }
  }
  for (const auto& n : mesh.normals)
    if (!(n.norm() > 0.5f)) {
      mesh.normals.clear();  // a zero normal somewhere: let the user compute them
      break;
    }
  checkNonEmpty(path, mesh);
  return mesh;
}

std::string extensionOf(const std::string& path) {
  const auto dot = path.find_last_of('.');
  return dot == std::string::npos ? std::string() : lower(path.substr(dot + 1));
}

void append(std::string& out, const void* data, std::size_t n) {
  out.append(static_cast<const char*>(data), n);
}

template <class T>
void appendLe(std::string& out, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  append(out, b, sizeof(T));
}

}  // namespace

TriangleMesh readObj(const std::string& path) { return parseObj(path, readFile(path, static_cast<std::size_t>(-1))); }

TriangleMesh readPly(const std::string& path) { return parsePly(path, readFile(path, static_cast<std::size_t>(-1))); }

TriangleMesh readMesh(const std::string& path) {
  const std::string ext = extensionOf(path);
  if (ext == "obj") return readObj(path);
  if (ext == "ply") return readPly(path);
  throw Error::inFile(path, 0, "unknown mesh format '." + ext + "' (expected .obj or .ply)");
}

void writeObj(const std::string& path, const TriangleMesh& mesh) {
  std::ostringstream s;
  s.precision(9);
  s << "# written by evio\n";
  for (const auto& p : mesh.positions) s << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : mesh.uvs) s << "vt " << t.x() << ' ' << t.y() << '\n';
  for (const auto& n : mesh.normals) s << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
  const bool uv = !mesh.uvs.empty(), nrm = !mesh.normals.empty();
  for (const auto& t : mesh.triangles) {
    s << 'f';
    for (int k = 0; k < 3; ++k) {
      const int i = t[k] + 1;
      s << ' ' << i;
      if (uv || nrm) s << '/';
      if (uv) s << i;
      if (nrm) s << '/' << i;
    }
    s << '\n';
  }
  writeFileAtomic(path, s.str());
}

void writePly(const std::string& path, const TriangleMesh& mesh) {
  const bool uv = !mesh.uvs.empty(), nrm = !mesh.normals.empty();
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by evio\n";
  out += "element vertex " + std::to_string(mesh.positions.size()) + "\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  if (nrm) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (uv) out += "property float u\nproperty float v\n";
  out += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) appendLe(out, mesh.positions[i][k]);
    if (nrm)
      for (int k = 0; k < 3; ++k) appendLe(out, mesh.normals[i][k]);
    if (uv)
      for (int k = 0; k < 2; ++k) appendLe(out, mesh.uvs[i][k]);
  }
  for (const auto& t : mesh.triangles) {
    appendLe(out, std::uint8_t{3});
    for (int k = 0; k < 3; ++k) appendLe(out, static_cast<std::int32_t>(t[k]));
  }
  writeFileAtomic(path, out);
}

}  // namespace evio::io
