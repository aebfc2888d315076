// SPDX-License-Identifier: GPL-3.0-or-later
// The only CGAL mesh headers of the project: reading and checking triangle meshes.
#include "app/io/mesh_io.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <charconv>
#include <cmath>
#include <cctype>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "app/io/atomic_file.hpp"
#include "app/io/bounded_read.hpp"
#include "core/format.hpp"
#include "app/io/text_escape.hpp"

namespace asperity {

using detail::num;

namespace {

/// Largest mesh file read: ~20 M triangles of ASCII OFF. A mesh body is the smooth shape under
/// the asperities; nothing asperity does needs more.
constexpr std::uint64_t kMaxMeshBytes = std::uint64_t{1} << 30;

/// The element counts an OFF or PLY header claims must fit in the file: every vertex or face takes
/// at least 6 bytes in any encoding ("0 0 0\n"; binary: 3 floats), so a header claiming 2e9
/// vertices in a small file is refused by name before the mesh library allocates for them.
void check_header_counts(const std::filesystem::path& file, std::uint64_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::istringstream is(head);
  std::string word;
  long double claimed = 0;
  if (!(is >> word)) return;
  if (word == "OFF") {
    std::string line;
    std::getline(is, line);
    while (std::getline(is, line)) {  // the first line that is not a comment holds the counts
      if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t\r")] == '#') continue;
      std::istringstream counts(line);
      long double nv = 0, nf = 0;
      if (counts >> nv >> nf) claimed = nv + nf;
      break;
    }
  } else if (word == "ply") {
    std::string line;
    while (std::getline(is, line) && line.rfind("end_header", 0) != 0) {
      std::istringstream e(line);
      std::string kw, name;
      long double n = 0;
      if (e >> kw >> name >> n && kw == "element") claimed += n;
    }
  }
  if (claimed * 6 > static_cast<long double>(size))
    throw std::invalid_argument("mesh file '" + file.string() + "': its header claims " + num(static_cast<double>(claimed)) +
                                " vertices and faces, more than its " + std::to_string(size) + " bytes can hold");
}

// ---- list counts: every count in the body of an OFF or PLY file bounded before CGAL reads it ----
//
// CGAL resizes a face's index vector to the count the file states before reading one index
// (OFF.h: resize(polygons[i], no); PLY_reader.h: m_buffer.resize(size)), so one face line
// "4000000000 0 2 1" in a 227-byte file made it allocate 12 GB. Each list is walked here first and
// its count bounded by what the rest of the file can hold: an ASCII item takes at least 2 bytes
// ("0 "), a binary one its type's size. So the items of all lists together never exceed the file's
// size (at most 1 GiB), whatever the counts claim. A face's vertex list is bounded besides by the
// vertices the header states (a polygon has no more corners than the mesh has vertices), which
// the memory estimate already covers (resources.cpp: vertices and faces from the header).

/// Reads a file in blocks; tracks the offset so that "the rest of the file" is known.
class MeshScan {
 public:
  MeshScan(const std::filesystem::path& file, std::uint64_t size) : in_(file, std::ios::binary), size_(size) {}
  std::uint64_t left() const { return size_ > pos_ ? size_ - pos_ : 0; }
  bool get(char& c) {
    if (at_ == end_ && !fill()) return false;
    c = buf_[at_++];
    ++pos_;
    return true;
  }
  bool line(std::string& l) {  // one line without its '\n'; false at the end of the file
    l.clear();
    char c = 0;
    bool any = false;
    while (get(c)) {
      any = true;
      if (c == '\n') return true;
      if (l.size() < kMaxLine) l += c;
    }
    return any;
  }
  bool token(std::string& t) {  // the next whitespace-separated word
    t.clear();
    char c = 0;
    bool got = false;
    while ((got = get(c)) && std::isspace(static_cast<unsigned char>(c))) {
    }
    if (!got) return false;
    do {
      if (t.size() < kMaxLine) t += c;
    } while (get(c) && !std::isspace(static_cast<unsigned char>(c)));
    return true;
  }
  bool bytes(unsigned char* out, std::size_t n) {
    char c = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!get(c)) return false;
      if (out) out[i] = static_cast<unsigned char>(c);
    }
    return true;
  }
  bool skip(std::uint64_t n) {
    if (n > left()) return false;
    const std::uint64_t in_buf = end_ - at_;
    if (n <= in_buf) return at_ += n, pos_ += n, true;
    pos_ += n, at_ = end_ = 0;
    in_.seekg(static_cast<std::streamoff>(pos_));
    return static_cast<bool>(in_);
  }

 private:
  static constexpr std::size_t kMaxLine = 256;  // a count is short; the rest of a long line is not kept
  bool fill() {
    in_.read(buf_, sizeof buf_);
    end_ = static_cast<std::size_t>(in_.gcount());
    at_ = 0;
    return end_ > 0;
  }
  std::ifstream in_;
  std::uint64_t size_, pos_ = 0;
  char buf_[1 << 16];
  std::size_t at_ = 0, end_ = 0;
};

[[noreturn]] void refuse_count(const std::filesystem::path& file, const std::string& where, const std::string& count,
                               const std::string& why) {
  throw std::invalid_argument("mesh file '" + file.string() + "': " + where + " claims " + count + " entries, " + why);
}

/// An unsigned decimal integer, or nullopt (a malformed count is left to CGAL, which refuses it).
std::optional<std::uint64_t> count_of(const std::string& t) {
  std::uint64_t v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec == std::errc::result_out_of_range) return std::numeric_limits<std::uint64_t>::max();
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::nullopt;
  return v;
}

/// A list count checked against the rest of the file (`item` bytes at least per entry) and, for a
/// face's vertex list, the mesh's vertex count.
void check_count(const std::filesystem::path& file, const std::string& where, std::uint64_t k, std::uint64_t item,
                 std::uint64_t left, std::uint64_t corners_max) {
  if (k > left / item + 1)
    refuse_count(file, where, std::to_string(k), "more than the " + std::to_string(left) + " bytes after it can hold");
  if (k > corners_max)
    refuse_count(file, where, std::to_string(k), "more corners than the mesh's " + std::to_string(corners_max) + " vertices");
}

void check_off_lists(const std::filesystem::path& file, std::uint64_t size) {
  MeshScan in(file, size);
  std::string l;
  auto content = [&](std::string& out) {  // the next line that is neither blank nor a comment
    while (in.line(out)) {
      const auto b = out.find_first_not_of(" \t\r");
      if (b != std::string::npos && out[b] != '#') return true;
    }
    return false;
  };
  if (!content(l)) return;
  if (l.find("BINARY") != std::string::npos)
    throw std::invalid_argument("mesh file '" + file.string() + "': binary OFF is not read (its list counts cannot be " +
                                "bounded before CGAL allocates for them); write it as ASCII OFF or PLY");
  std::istringstream head(l);
  std::string tok;
  std::vector<std::uint64_t> n;
  while (head >> tok) {  // "OFF" and the counts may share the first line
    if (tok.ends_with("OFF")) continue;
    if (auto v = count_of(tok)) n.push_back(*v);
  }
  if (n.size() < 2 && content(l)) {
    std::istringstream counts(l);
    while (n.size() < 2 && counts >> tok)
      if (auto v = count_of(tok)) n.push_back(*v);
  }
  if (n.size() < 2) return;  // CGAL refuses it
  for (std::uint64_t i = 0; i < n[0]; ++i)
    if (!content(l)) return;
  for (std::uint64_t i = 0; i < n[1]; ++i) {
    const std::uint64_t left = in.left();  // bytes from this face's line on
    if (!content(l)) return;
    std::istringstream face(l);
    if (!(face >> tok)) return;
    const auto k = count_of(tok);
    if (!k) return;
    check_count(file, "face " + std::to_string(i), *k, 2, left, n[0]);
  }
}

/// The size of a PLY scalar type, 0 if it is not one.
std::uint64_t ply_type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

struct PlyProperty {
  std::uint64_t size = 0;       // a scalar's size; a list's item size
  std::uint64_t count_size = 0; // a list's count type size; 0 for a scalar
  std::string name;
};
struct PlyElement {
  std::string name;
  std::uint64_t rows = 0;
  std::vector<PlyProperty> props;
};

std::uint64_t binary_count(const unsigned char* b, std::uint64_t n, bool big_endian) {
  std::uint64_t v = 0;
  for (std::uint64_t i = 0; i < n; ++i) v |= std::uint64_t{b[big_endian ? n - 1 - i : i]} << (8 * i);
  return v;  // signed count types: a negative count reads as a huge one and is refused
}

void check_ply_lists(const std::filesystem::path& file, std::uint64_t size) {
  MeshScan in(file, size);
  std::string l;
  int format = -1;  // 0 ascii, 1 little endian, 2 big endian
  std::vector<PlyElement> elements;
  std::uint64_t vertices = 0;
  // A header this check cannot follow is refused, not passed on: CGAL reads such files anyway
  // (a first line "\x01ply", a property of type "floax"), with list counts nobody bounded
  // (fuzz_mesh_file: 4e9-element lists from a misparsed layout, out of memory).
  const auto refuse = [&](const std::string& why) {
    throw std::invalid_argument("mesh file '" + file.string() + "': " + why +
                                " (PLY headers are checked before reading: ply, format, element, property lines)");
  };
  for (bool first = true; in.line(l); first = false) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    if (first && l != "ply") refuse("the first line is not \"ply\"");
    std::istringstream w(l);
    std::string kw, a, b, c;
    w >> kw;
    if (kw == "end_header") break;
    if (kw != "format" && kw != "element" && kw != "property" && kw != "comment" && kw != "obj_info" && !(first && kw == "ply"))
      refuse("a header line that is not ply, format, comment, obj_info, element or property: '" + detail::escaped(l) + "'");
    if (kw == "property" && elements.empty()) refuse("a property before any element");
    if (kw == "format" && w >> a) format = a == "ascii" ? 0 : a == "binary_little_endian" ? 1 : a == "binary_big_endian" ? 2 : -1;
    if (kw == "element" && w >> a >> b) {
      const auto rows = count_of(b);
      if (!rows) refuse("element '" + a + "' has no readable count");
      elements.push_back({a, *rows, {}});
      if (a == "vertex") vertices = *rows;
    }
    if (kw == "property" && !elements.empty() && w >> a) {
      PlyProperty p;
      if (a == "list" && w >> b >> c) {
        p.count_size = ply_type_size(b), p.size = ply_type_size(c);
        if (p.count_size == 0 || p.size == 0) refuse("a list property of unknown type (" + b + ", " + c + ")");
      } else {
        p.size = ply_type_size(a);
        if (p.size == 0) refuse("a property of unknown type '" + a + "'");
      }
      w >> p.name;
      elements.back().props.push_back(p);
    }
  }
  if (format < 0) refuse("no known format line (ascii, binary_little_endian, binary_big_endian)");
  std::string tok;
  unsigned char buf[8];
  for (const auto& e : elements)
    for (std::uint64_t r = 0; r < e.rows; ++r)
      for (const auto& p : e.props) {
        const std::string where = e.name + " " + std::to_string(r) + " '" + p.name + "'";
        const std::uint64_t corners = e.name == "face" ? vertices : std::numeric_limits<std::uint64_t>::max();
        if (format == 0) {
          if (!in.token(tok)) return;
          if (p.count_size == 0) continue;
          const auto k = count_of(tok);
          if (!k) return;
          check_count(file, where, *k, 2, in.left(), corners);
          for (std::uint64_t i = 0; i < *k; ++i)
            if (!in.token(tok)) return;
        } else if (p.count_size == 0) {
          if (!in.skip(p.size)) return;
        } else {
          if (!in.bytes(buf, p.count_size)) return;
          const std::uint64_t k = binary_count(buf, p.count_size, format == 2);
          check_count(file, where, k, p.size, in.left(), corners);
          if (!in.skip(k * p.size)) return;
        }
      }
}

/// Every list count of an OFF or PLY file bounded (the other formats state no counts CGAL trusts:
/// OBJ faces are their tokens, STL faces are triangles).
void check_list_counts(const std::filesystem::path& file, std::uint64_t size) {
  std::string ext = file.extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".off") check_off_lists(file, size);
  if (ext == ".ply") check_ply_lists(file, size);
}

// CGAL's read_polygon_mesh (CGAL 5.5, Polygon_mesh_processing/IO/polygon_mesh_io.h) step by step,
// with one check it lacks: every face's vertex index names a vertex of the file. repair_polygon_soup
// indexes the points with the file's indices unchecked, so a PLY face naming vertex -889192445 read
// outside the point array (found by fuzz_mesh_file). Same steps, same mesh otherwise.
bool read_checked_soup(const std::string& f, CGAL::Surface_mesh<CGAL::Exact_predicates_inexact_constructions_kernel::Point_3>& sm) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  std::vector<CGAL::Exact_predicates_inexact_constructions_kernel::Point_3> points;
  std::vector<std::vector<std::size_t>> faces;
  if (!CGAL::IO::read_polygon_soup(f, points, faces)) return false;
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (const std::size_t v : faces[i])
      if (v >= points.size())
        throw std::invalid_argument("mesh file '" + f + "': face " + std::to_string(i) + " names vertex " +
                                    std::to_string(static_cast<long long>(v)) + ", but the file has " +
                                    std::to_string(points.size()) + " vertices");
  PMP::repair_polygon_soup(points, faces);
  PMP::orient_polygon_soup(points, faces);
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) return false;
  PMP::polygon_soup_to_polygon_mesh(points, faces, sm);
  return true;
}

}  // namespace

TriangleMesh read_mesh(const std::filesystem::path& file, double scale) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  const std::string f = file.string();
  if (!std::isfinite(scale) || scale <= 0) throw std::invalid_argument("mesh scale must be finite and > 0, got " + num(scale));
  std::uint64_t size = 0;
  try {
    size = checked_input_size(file, kMaxMeshBytes, "mesh file");
  } catch (const InputFileError& e) {
    throw std::invalid_argument(e.what());
  }
  check_header_counts(file, size);
  check_list_counts(file, size);
  Mesh sm;
  bool read = false;
  try {
    read = read_checked_soup(f, sm);
  } catch (const std::bad_alloc&) {
    throw std::invalid_argument("mesh file '" + f + "': not enough memory to read it (" + std::to_string(size) + " bytes)");
  }
  if (!read || sm.number_of_faces() == 0)
    throw std::invalid_argument("mesh file '" + f + "' could not be read as a polygon mesh (OFF, PLY, STL, OBJ)");
  if (!CGAL::is_triangle_mesh(sm)) throw std::invalid_argument("mesh '" + f + "' is not a triangle mesh");
  if (!CGAL::is_closed(sm)) throw std::invalid_argument("mesh '" + f + "' is not closed (it has border edges)");
  if (CGAL::Polygon_mesh_processing::does_self_intersect(sm))
    throw std::invalid_argument("mesh '" + f + "' intersects itself");
  TriangleMesh m;
  std::vector<std::uint32_t> id(sm.number_of_vertices() + sm.number_of_removed_vertices(), 0);
  for (auto v : sm.vertices()) {
    const auto& p = sm.point(v);
    id[v.idx()] = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.emplace_back(scale * p.x(), scale * p.y(), scale * p.z());
  }
  for (auto fc : sm.faces()) {
    std::array<std::uint32_t, 3> t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(fc), sm)) t[static_cast<std::size_t>(k++)] = id[v.idx()];
    m.faces.push_back(t);
  }
  // A closed, consistently oriented mesh has volume of one sign; outward means positive.
  double vol = 0;
  for (const auto& t : m.faces) vol += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  if (!(vol > 0)) throw std::invalid_argument("mesh '" + f + "' is not outward oriented (volume " + num(vol) + " m^3)");
  return m;
}

namespace {

// %.9g, what the export always wrote (ostream precision 9): 1 nm at 1 m.
constexpr std::uint64_t kPlyNumber = 16;  // the widest: "-1.23456789e-100"
void put(std::string& s, double v) {
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::general, 9);
  s.append(b, r.ptr);
}
void put(std::string& s, std::uint64_t v) {
  char b[24];
  const auto r = std::to_chars(b, b + sizeof b, v);
  s.append(b, r.ptr);
}
std::uint64_t digits(std::uint64_t v) { return v < 10 ? 1 : 1 + digits(v / 10); }
void put_point(std::string& s, const Vec3& p) {
  put(s, p.x()), s += ' ', put(s, p.y()), s += ' ', put(s, p.z());
}
void put_face(std::string& s, std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  s += "3 ", put(s, a), s += ' ', put(s, b), s += ' ', put(s, c), s += '\n';
}
constexpr std::uint64_t kPlyHeaderMax = 400;  // the header lines without the body's name

}  // namespace

std::uint64_t ply_text_bytes(std::uint64_t n, PlyStyle style, std::uint64_t nbv, std::uint64_t nbf) {
  const std::uint64_t line3 = 3 * (kPlyNumber + 1);  // "x y z\n"
  if (style == PlyStyle::points) return kPlyHeaderMax + n * (4 * (kPlyNumber + 1));
  const std::uint64_t face = 2 + 3 * (digits(12 * n + nbv) + 1);
  return kPlyHeaderMax + (12 * n + nbv) * line3 + (20 * n + nbf) * face;
}

namespace {

// OFF: "[ST][C][N][4][n]OFF" then the counts (comments '#' to the end of a line).
MeshFileSize off_size(std::istream& in) {
  MeshFileSize z;
  std::string tok;
  std::vector<std::uint64_t> n;
  for (std::string line; n.size() < 2 && std::getline(in, line);) {
    std::istringstream ls(line.substr(0, line.find('#')));
    while (n.size() < 2 && ls >> tok) {
      if (tok.ends_with("OFF")) continue;
      std::uint64_t v = 0;
      const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      if (r.ec != std::errc() || r.ptr != tok.data() + tok.size()) return z;
      n.push_back(v);
    }
  }
  if (n.size() == 2) z.vertices = n[0], z.faces = n[1];
  return z;
}

// PLY (ASCII or binary: the header is text either way): "element vertex N", "element face N".
MeshFileSize ply_size(std::istream& in) {
  MeshFileSize z;
  for (std::string line; std::getline(in, line) && !line.starts_with("end_header");) {
    std::istringstream ls(line);
    std::string element, name;
    std::uint64_t v = 0;
    if (!(ls >> element >> name >> v) || element != "element") continue;
    if (name == "vertex") z.vertices = v;
    if (name == "face") z.faces = v;
  }
  return z;
}

// Lines counted: OBJ "v " / "f ", ASCII STL "facet" (3 vertices each, merged later).
MeshFileSize counted_size(std::istream& in, bool stl) {
  MeshFileSize z;
  for (std::string line; std::getline(in, line);) {
    const auto b = line.find_first_not_of(" \t");
    if (b == std::string::npos) continue;
    const std::string_view l = std::string_view(line).substr(b);
    if (stl) {
      if (l.starts_with("facet")) ++z.faces, z.vertices += 3;
    } else if (l.starts_with("v ")) {
      ++z.vertices;
    } else if (l.starts_with("f ")) {
      ++z.faces;
    }
  }
  return z;
}

}  // namespace

MeshFileSize mesh_file_size(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};
  std::string ext = file.extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".off") return off_size(in);
  if (ext == ".ply") return ply_size(in);
  if (ext == ".obj") return counted_size(in, false);
  if (ext != ".stl") return {};
  // Binary STL: an 80-byte header, the face count, 50 bytes per face.
  char head[84] = {};
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  if (in.read(head, sizeof head)) {
    std::uint32_t n = 0;
    std::memcpy(&n, head + 80, sizeof n);
    if (!ec && bytes == 84 + 50 * std::uint64_t(n)) return {3 * std::uint64_t(n), n};
  }
  in.clear();
  in.seekg(0);
  return counted_size(in, true);
}

void write_ply(const std::filesystem::path& file, const RoughBody& b, PlyStyle style, double inflate,
               const TriangleMesh* base, const Vec3& base_offset) {
  if (!std::isfinite(inflate) || inflate <= 0) throw std::invalid_argument("inflate must be finite and > 0, got " + num(inflate));
  const std::size_t nbv = base ? base->vertices.size() : 0, nbf = base ? base->faces.size() : 0;
  // One allocation of the bound: no copy while growing (pages never written stay unmapped), and a
  // failure is std::bad_alloc here, never a silently short text (an ostringstream that cannot grow
  // sets badbit and drops the rest).
  std::string os;
  const std::uint64_t bound =
      4 * b.name.size() + ply_text_bytes(b.size(), style, style == PlyStyle::points ? 0 : nbv, style == PlyStyle::points ? 0 : nbf);
  try {
    os.reserve(bound);
  } catch (const std::bad_alloc&) {  // named: the export is what did not fit
    throw std::runtime_error("cannot write " + file.string() + ": out of memory for its text (up to " +
                             std::to_string(bound / 1000000) + " MB; outputs.export_style = \"points\" is ~15x smaller)");
  }
  // The body's name (the mesh file's) escaped: a newline in it would end the comment and write
  // header lines of its own ("element vertex 0\nend_header"); a PLY header is ASCII.
  os += "ply\nformat ascii 1.0\ncomment asperity rough body '" + detail::escaped(b.name, true, true) + "', body frame, metres\n";
  if (style == PlyStyle::points) {
    os += "element vertex " + std::to_string(b.size()) +
          "\nproperty double x\nproperty double y\nproperty double z\nproperty double radius\nend_header\n";
    for (std::size_t i = 0; i < b.size(); ++i) {
      put_point(os, b.centres[i]);
      os += ' ', put(os, b.radii[i]), os += '\n';
    }
  } else {
    // Unit icosahedron.
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3> iv{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (auto& v : iv) v.normalize();
    const int ifc[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    os += "element vertex " + std::to_string(12 * b.size() + nbv) +
          "\nproperty double x\nproperty double y\nproperty double z\nelement face " + std::to_string(20 * b.size() + nbf) +
          "\nproperty list uchar int vertex_indices\nend_header\n";
    for (std::size_t i = 0; i < b.size(); ++i)
      for (const Vec3& v : iv) put_point(os, b.centres[i] + inflate * b.radii[i] * v), os += '\n';
    for (std::size_t k = 0; k < nbv; ++k) put_point(os, base->vertices[k] + base_offset), os += '\n';
    for (std::uint64_t i = 0; i < b.size(); ++i)
      for (const auto& f : ifc) put_face(os, 12 * i + f[0], 12 * i + f[1], 12 * i + f[2]);
    const std::uint64_t o = 12 * b.size();
    for (std::size_t k = 0; k < nbf; ++k) put_face(os, o + base->faces[k][0], o + base->faces[k][1], o + base->faces[k][2]);
  }
  write_file_atomic(file, os);
}

}  // namespace asperity
