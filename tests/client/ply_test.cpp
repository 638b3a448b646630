// The PLY reader of `hapticctl import` (client/ply.h): the three encodings give the same
// triangles; polygons are fanned, triangle strips unrolled with their winding kept; properties
// and elements it does not use are skipped by their types; bad files are refused saying what
// and where, before anything is reserved for a count the file cannot hold.
#include "client/ply.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using hapticd::client::parsePly;
using hapticd::decomp::Triangle;
using hapticd::decomp::TriangleMesh;

// a unit cube's 8 corners and its 6 faces as quads, each turned outward
const double kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                              {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
const int kQuad[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                         {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};

// the cube written with extra properties of every type around x, y, z (a normal, a colour, a
// short), its faces' lists with a uchar count and int indices followed by a float property, and
// an element the reader does not use (edges) between the vertices and the faces
std::string cubeHeader(const char* format) {
  return std::string("ply\r\nformat ") + format +
         " 1.0\r\ncomment made by a test\r\nobj_info nothing\r\n"
         "element vertex 8\r\nproperty uchar red\r\nproperty double x\r\nproperty float y\r\n"
         "property short flags\r\nproperty int z\r\nproperty list ushort uint tags\r\n"
         "element edge 2\r\nproperty int vertex1\r\nproperty int vertex2\r\n"
         "element face 6\r\nproperty list uchar int vertex_indices\r\nproperty float quality\r\n"
         "end_header\r\n";
}

std::string asciiCube() {
  std::string s = cubeHeader("ascii");
  for (const auto& c : kCorner)
    s += "255 " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " -7 " +
         std::to_string(static_cast<int>(c[2])) + " 2 9 10\n";
  s += "0 1\n1 2\n";
  for (const auto& q : kQuad)
    s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
         " " + std::to_string(q[3]) + " 0.5\n";
  return s;
}

template <class T>
void put(std::string& s, T value, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big != (std::endian::native == std::endian::big))
    std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

std::string binaryCube(bool big) {
  std::string s = cubeHeader(big ? "binary_big_endian" : "binary_little_endian");
  for (const auto& c : kCorner) {
    put<std::uint8_t>(s, 255, big);
    put<double>(s, c[0], big);
    put<float>(s, static_cast<float>(c[1]), big);
    put<std::int16_t>(s, -7, big);
    put<std::int32_t>(s, static_cast<std::int32_t>(c[2]), big);
    put<std::uint16_t>(s, 2, big);
    put<std::uint32_t>(s, 9, big);
    put<std::uint32_t>(s, 10, big);
  }
  for (int e = 0; e < 2; ++e) {
    put<std::int32_t>(s, e, big);
    put<std::int32_t>(s, e + 1, big);
  }
  for (const auto& q : kQuad) {
    put<std::uint8_t>(s, 4, big);
    for (int k = 0; k < 4; ++k)
      put<std::int32_t>(s, q[k], big);
    put<float>(s, 0.5f, big);
  }
  return s;
}

// the signed volume of a closed mesh (positive when every triangle turns outward)
double volume(const TriangleMesh& m) {
  double v = 0.0;
  for (const Triangle& t : m.triangles) {
    const auto& a = m.positions[t[0]];
    const auto& b = m.positions[t[1]];
    const auto& c = m.positions[t[2]];
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

TEST(Ply, TheThreeEncodingsGiveTheSameFannedCube) {
  const std::string files[3] = {asciiCube(), binaryCube(false), binaryCube(true)};
  for (const std::string& bytes : files) {
    const auto r = parsePly(bytes, "cube.ply");
    ASSERT_TRUE(r.ok()) << r.error().message;
    const TriangleMesh& m = r.value();
    ASSERT_EQ(m.positions.size(), 8u);
    for (std::size_t k = 0; k < 8; ++k) {
      EXPECT_EQ(m.positions[k].x, kCorner[k][0]);
      EXPECT_EQ(m.positions[k].y, kCorner[k][1]);
      EXPECT_EQ(m.positions[k].z, kCorner[k][2]);
    }
    ASSERT_EQ(m.triangles.size(), 12u);
    for (std::size_t f = 0; f < 6; ++f) {
      const auto& q = kQuad[f];
      EXPECT_EQ(m.triangles[2 * f],
                (Triangle{std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])}));
      EXPECT_EQ(m.triangles[2 * f + 1],
                (Triangle{std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])}));
    }
    EXPECT_DOUBLE_EQ(volume(m), 1.0);
  }
}

// binary data whose first byte is a newline (assimp 5.2 aborted on such a file): read as it is
TEST(Ply, BinaryDataMayStartWithANewlineByte) {
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 4\n"
      "property list uchar int vertex_index\nend_header\n";
  const float v[4][3] = {{0.01f, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::uint8_t first = 0;
  std::memcpy(&first, &v[0][0], 1);
  ASSERT_EQ(first, 0x0a);
  for (const auto& p : v)
    for (float x : p)
      put<float>(s, x, false);
  const std::int32_t t[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& tri : t) {
    put<std::uint8_t>(s, 3, false);
    for (std::int32_t i : tri)
      put<std::int32_t>(s, i, false);
  }
  const auto r = parsePly(s, "nl.ply");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r.value().positions[0].x, 0.01f);
  EXPECT_EQ(r.value().triangles.size(), 4u);
  EXPECT_GT(volume(r.value()), 0.0);
}

// strips (Stanford's scans): -1 restarts, the odd triangles of a run turned back so that the
// winding stays, the joining triangles (a vertex twice) left out
TEST(Ply, TriangleStripsUnrollWithTheirWinding) {
  // a closed tetrahedron as one strip, then a quad as a strip after a restart and a joining
  // triangle (7 7 repeated)
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
      "property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n5 5 5\n6 5 5\n5 6 5\n6 6 5\n"
      "13 0 1 2 3 0 1 -1 4 5 6 7 7 7\n";
  const auto r = parsePly(s, "strips.ply");
  ASSERT_TRUE(r.ok()) << r.error().message;
  const std::vector<Triangle> want = {{0, 1, 2}, {2, 1, 3}, {2, 3, 0},
                                      {0, 3, 1}, {4, 5, 6}, {6, 5, 7}};
  EXPECT_EQ(r.value().triangles, want);
  TriangleMesh tetra = r.value();
  tetra.triangles.resize(4);
  EXPECT_NEAR(std::abs(volume(tetra)), 1.0 / 6.0, 1e-12);
  // every edge of the tetrahedron is used once each way (counted from both of its triangles:
  // 6 edges x 2): one winding throughout
  int opposed = 0;
  for (const Triangle& a : tetra.triangles)
    for (const Triangle& b : tetra.triangles)
      for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j)
          opposed += a[i] == b[(j + 1) % 3] && a[(i + 1) % 3] == b[j] ? 1 : 0;
  EXPECT_EQ(opposed, 12);
}

// an L-shaped face listed from a corner whose fan folds over the notch: ear-clipped, every
// triangle turning as the face does and their areas adding up to the face's (no part twice)
TEST(Ply, ANonConvexFaceIsNotFolded) {
  const char* corners = "0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n";
  for (int first = 0; first < 6; ++first) {
    std::string s =
        "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    s += corners;
    s += "6";
    for (int k = 0; k < 6; ++k)
      s += " " + std::to_string((first + k) % 6);
    s += "\n";
    const auto r = parsePly(s, "l.ply");
    ASSERT_TRUE(r.ok()) << r.error().message;
    const TriangleMesh& m = r.value();
    ASSERT_EQ(m.triangles.size(), 4u) << first;
    double area = 0.0;
    for (const Triangle& t : m.triangles) {
      const double z =
          glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]])
              .z;
      EXPECT_GT(z, 0.0) << "folded triangle, listed from corner " << first;
      area += 0.5 * std::abs(z);
    }
    EXPECT_DOUBLE_EQ(area, 3.0) << first;
  }
}

// what other readers accept: a header line of free text (Blender 2.4 wrote one without the comment
// keyword), ASCII lines with more words than the header's properties (the words left over)
TEST(Ply, WhatOtherReadersAcceptIsRead) {
  const std::string s =
      "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nproperty uchar red\nend_header\n"
      "0 0 0 1 2\n\n1 0 0\n0 1 0\n3 0 1 2 9 1 1 1 1\n";
  const auto r = parsePly(s, "lenient.ply");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r.value().positions.size(), 3u);
  EXPECT_EQ(r.value().positions[1].x, 1.0);
  EXPECT_EQ(r.value().triangles, (std::vector<Triangle>{{0, 1, 2}}));
}

// an index outside the vertices is kept (the decomposition's repair drops and counts it); a
// negative one is no vertex
TEST(Ply, IndicesOutsideTheVerticesArePassedOnForTheRepair) {
  const std::string s =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 9 -2\n";
  const auto r = parsePly(s, "bad.ply");
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r.value().triangles.size(), 2u);
  EXPECT_EQ(r.value().triangles[1][1], 9u);
  EXPECT_EQ(r.value().triangles[1][2], 0xffffffffu);
}

TEST(Ply, BadFilesAreRefusedSayingWhatAndWhere) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  std::string whole = header;
  for (int k = 0; k < 9; ++k)
    put<float>(whole, static_cast<float>(k), false);
  put<std::uint8_t>(whole, 3, false);
  for (std::int32_t i = 0; i < 3; ++i)
    put<std::int32_t>(whole, i, false);
  ASSERT_TRUE(parsePly(whole, "f.ply").ok());

  struct Case {
    std::string bytes;
    const char* says;
  };
  const Case cases[] = {
      {"solid x\n", "not a PLY file"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "no end_header"},
      {"ply\nformat zip 1.0\nend_header\n", "line 2: unknown format 'zip'"},
      {"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", "line 3"},
      {"ply\nformat ascii 1.0\nproperty float x\nend_header\n", "property before any element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty flt x\nend_header\n", "line 4"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int i\nend_header\n",
       "line 4"},
      {"ply\nformat ascii 1.0\nelemnt vertex 1\nend_header\n", "no vertex element"},
      {"", "the file is empty"},
      {"ply\nelement vertex 0\nend_header\n", "before a format line"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "end_header\n0 0\n",
       "no x, y and z"},
      {"ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n"
       "end_header\n",
       "no vertex element"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty int material\nend_header\n0 0 0\n1\n",
       "no vertex_indices"},
      {"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0 0 0\n1 one 0\n",
       "element vertex, 2 of 2"},
      {whole.substr(0, whole.size() - 3), "element face, 1 of 1"},
      {header.substr(0, header.find("element vertex 3")) + "element vertex 4000000000\n" +
           header.substr(header.find("property float x")) + whole.substr(header.size()),
       "more than the file holds"},
      {header + whole.substr(header.size(), 36) + std::string("\xff") + std::string(4, '\0'),
       "element face, 1 of 1"},
  };
  for (const Case& c : cases) {
    const auto r = parsePly(c.bytes, "bad.ply");
    ASSERT_FALSE(r.ok()) << c.says;
    EXPECT_NE(r.error().message.find("bad.ply: "), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(c.says), std::string::npos)
        << "want '" << c.says << "' in: " << r.error().message;
  }
}

// mutated files (bytes changed, cut short, lines doubled) either read or are refused with the
// file's name: never a crash or a read past the bytes (the AddressSanitizer run sees those)
TEST(Ply, MutatedFilesReadOrAreRefused) {
  const std::string seeds[] = {asciiCube(), binaryCube(false), binaryCube(true),
                               "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                               "property float y\nproperty float z\nelement tristrips 1\n"
                               "property list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n"
                               "0 1 0\n0 0 1\n6 0 1 2 3 0 1\n"};
  std::mt19937 rng(20261204);
  int read = 0, refused = 0;
  for (const std::string& seed : seeds) {
    for (int n = 0; n < 3000; ++n) {
      std::string b = seed;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits && !b.empty(); ++e) {
        const std::size_t at = rng() % b.size();
        switch (rng() % 4) {
          case 0:
            b[at] = static_cast<char>(rng() & 0xff);
            break;
          case 1:
            b.resize(at);
            break;
          case 2:
            b.insert(at, b.substr(at, rng() % 16));
            break;
          default:
            b[at] = "0123456789 -\n"[rng() % 13];
        }
      }
      const auto r = parsePly(b, "m.ply");
      if (r.ok()) {
        ++read;
      } else {
        ++refused;
        EXPECT_EQ(r.error().message.rfind("m.ply: ", 0), 0u) << r.error().message;
      }
    }
  }
  std::printf("  %d mutated files read, %d refused\n", read, refused);
  EXPECT_GT(read, 0);
  EXPECT_GT(refused, 0);
}

}  // namespace
