#include "evio/core/io/mesh_file.h"

#include <gtest/gtest.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "temp_dir.h"

namespace evio {
namespace {

TriangleMesh sampleMesh(bool normals, bool uvs) {
  TriangleMesh m;
  m.positions = {{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {1.f, 1.f, 0.25f}, {0.f, 1.f, -1e-3f}, {0.1f, 0.2f, 3.3f}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}};
  if (normals)
    for (std::size_t i = 0; i < m.positions.size(); ++i)
      m.normals.push_back(Eigen::Vector3f(0.1f * static_cast<float>(i), 0.3f, 1.0f).normalized());
  if (uvs)
    for (std::size_t i = 0; i < m.positions.size(); ++i)
      m.uvs.emplace_back(0.125f * static_cast<float>(i), 1.0f / 3.0f);
  return m;
}

void expectSame(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  ASSERT_EQ(a.uvs.size(), b.uvs.size());
  // Both formats store single precision exactly (OBJ with 9 digits).
  for (std::size_t i = 0; i < a.positions.size(); ++i) EXPECT_EQ(a.positions[i], b.positions[i]) << i;
  for (std::size_t i = 0; i < a.triangles.size(); ++i) EXPECT_EQ(a.triangles[i], b.triangles[i]) << i;
  for (std::size_t i = 0; i < a.normals.size(); ++i) EXPECT_NEAR((a.normals[i] - b.normals[i]).norm(), 0.f, 1e-7f);
  for (std::size_t i = 0; i < a.uvs.size(); ++i) EXPECT_EQ(a.uvs[i], b.uvs[i]) << i;
}

TEST(MeshFile, ObjAndPlyRoundTrip) {
  test::TempDir dir;
  for (bool normals : {false, true})
    for (bool uvs : {false, true}) {
      const TriangleMesh m = sampleMesh(normals, uvs);
      io::writeObj(dir.file("m.obj"), m);
      expectSame(m, io::readMesh(dir.file("m.obj")));
      io::writePly(dir.file("m.ply"), m);
      expectSame(m, io::readMesh(dir.file("m.ply")));
    }
}

TEST(MeshFile, ObjPolygonsNegativeIndicesAndFaceVaryingAttributes) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("q.obj"),
                      "# a quad and a triangle\n"
                      "o thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
                      "usemtl x\ns off\n"
                      "f 1/1 2/2 3/3 4/4\n"
                      "f -4/5 -3/2 -1/4\n");
  const TriangleMesh m = io::readObj(dir.file("q.obj"));
  ASSERT_EQ(m.triangles.size(), 3u);  // quad fan-triangulated + triangle
  // Vertex 1 appears with uv 1 and uv 5: two distinct vertices.
  EXPECT_EQ(m.positions.size(), 5u);
  EXPECT_EQ(m.uvs.size(), 5u);
  const auto& t = m.triangles[2];
  EXPECT_EQ(m.positions[static_cast<std::size_t>(t[0])], Eigen::Vector3f(0, 0, 0));
  EXPECT_EQ(m.uvs[static_cast<std::size_t>(t[0])], Eigen::Vector2f(0.5f, 0.5f));
  EXPECT_EQ(m.positions[static_cast<std::size_t>(t[2])], Eigen::Vector3f(0, 1, 0));
}

TEST(MeshFile, AsciiPlyWithExtraPropertiesAndElements) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("a.ply"),
                      "ply\nformat ascii 1.0\ncomment hello\n"
                      "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
                      "property uchar red\nproperty float s\nproperty float t\n"
                      "element face 1\nproperty list uchar int vertex_indices\nproperty int flags\n"
                      "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                      "end_header\n"
                      "0 0 0 255 0 0\n2 0 0 0 1 0\n2 2 0 7 1 1\n0 2 0 8 0 1\n"
                      "4 0 1 2 3 99\n"
                      "0 1\n");
  const TriangleMesh m = io::readPly(dir.file("a.ply"));
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.positions[2], Eigen::Vector3f(2, 2, 0));
  EXPECT_EQ(m.uvs[1], Eigen::Vector2f(1, 0));
}

void expectError(const std::string& path, const std::string& part1, const std::string& part2) {
  try {
    io::readMesh(path);
    FAIL() << "expected an error for " << path;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(part1), std::string::npos) << msg;
    EXPECT_NE(msg.find(part2), std::string::npos) << msg;
  }
}

TEST(MeshFile, BadInputNamesFileAndLine) {
  test::TempDir dir;
  expectError(dir.file("missing.obj"), "missing.obj", "cannot open");
  io::writeFileAtomic(dir.file("idx.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expectError(dir.file("idx.obj"), "idx.obj:4", "out of range");
  io::writeFileAtomic(dir.file("num.obj"), "v 0 0 0\nv 1 x 0\n");
  expectError(dir.file("num.obj"), "num.obj:2", "malformed number");
  io::writeFileAtomic(dir.file("none.obj"), "v 0 0 0\n");
  expectError(dir.file("none.obj"), "none.obj", "no triangles");
  io::writeFileAtomic(dir.file("trunc.ply"),
                      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                      "property float y\nproperty float z\nend_header\nabc");
  expectError(dir.file("trunc.ply"), "trunc.ply", "truncated");
  io::writeFileAtomic(dir.file("x.stl"), "solid\n");
  expectError(dir.file("x.stl"), "x.stl", "unknown mesh format");
}

}  // namespace
}  // namespace evio
