// Fills one n-sided network case (bench/peers/network_cases.py) with the surfaces of Péter
// Salvi's transfinite library and prints one JSON line per surface type. Built by
// bench/peers/build_salvi.sh; salvi_fill.py runs it over many cases and prints a table.
//
// usage: salvi_fill CASE.json [--repeat K] [--resolution R] [--types a,b,...]
//                   [--fences corner|raw]
//
// Boundary curves: every side is a cubic spline through the case's points at chord-length
// parameters on [0, 1], clamped at each end to the slope of the cubic through the four nearest
// points -- the same curve pdeshape's bench (crates/pdeshape/benches/tools/nsided_cases.rs)
// builds, so both fill the same boundary.
//
// Ribbons: the library's own (RibbonCompatibleWithHandler for the transfinite patches: a cross
// derivative quadratic in s through the neighbouring sides' end tangents and a middle handler,
// projected into the plane normal to the side's normal fence). A side with normals gets them as
// its normal fence (Ribbon::overrideNormalFence): the same clamped spline through the case's
// normals, normalised, as a function of the side's parameter. A side without normals keeps the
// library's rotation-minimising frame between the corner normals.
//
// Surface types (--types, default all):
//   sb  SurfaceSideBased        (Kato-type side-based patch)
//   cb  SurfaceCornerBased      (Charrot-Gregory-type corner-based patch)
//   gc  SurfaceGeneralizedCoons
//   cr  SurfaceCompositeRibbon
//   mp  SurfaceMidpoint
//   mc  SurfaceMidpointCoons
//   el  SurfaceElastic          (Sabin's elastic patch)
//   ha  SurfaceHarmonic         (discrete harmonic mesh; positions only, G0)
//   bh  SurfaceBiharmonic       (discrete biharmonic mesh from the boundary and the fences)
//
// Figures, per type:
//   boundary   largest distance from the case's points to the surface at their parameters
//              (the surface evaluated at the domain's edge point of that parameter). For the
//              discrete meshes (ha, bh): largest distance from the case's points to the mesh's
//              boundary polygon.
//   g1         largest angle (radians, between lines) between the surface normal and the case's
//              normal at the case's points, corners excluded. The normal is the cross product of
//              the surface's derivatives along the domain edge (central difference) and into the
//              domain (one-sided, second order), step h = 3e-5 of the domain edge's length.
//              g1_fd_change is the largest change of that angle from step 2h to h (the size of
//              the difference error); g1_side, g1_t say where the largest angle is. null for
//              the discrete meshes (no derivatives to take).
//   fences     corner or raw (--fences, default corner): see fence() below.
//   truth_max, truth_rms   distance from the vertices of the library's own tessellation
//              (Surface::eval(R), R = --resolution, default 40) to the truth surface.
//   build_median_s  wall time, median over --repeat runs (default 7), of making the surface:
//              construction, setCurves, setupLoop, the normal fences and update(); for ha and
//              bh it includes eval(R), where these surfaces are solved.
//   update_median_s  update() alone on a built surface (what an edit of one side costs at most).
//   mesh_median_s    eval(R) on a built surface (the continuous types evaluate lazily: this is
//              where their time goes), with mesh_points the number of vertices.
//
// Exit status 0, 1 when the case cannot be read (one line on stderr naming the place), 2 on a
// usage error.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "domain.hh"
#include "parameterization.hh"
#include "ribbon.hh"
#include "surface-biharmonic.hh"
#include "surface-composite-ribbon.hh"
#include "surface-corner-based.hh"
#include "surface-elastic.hh"
#include "surface-generalized-coons.hh"
#include "surface-harmonic.hh"
#include "surface-midpoint-coons.hh"
#include "surface-midpoint.hh"
#include "surface-side-based.hh"

using namespace Transfinite;

// ---------------------------------------------------------------- a small JSON reader

struct Json {
  enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
  double number = 0;
  bool boolean = false;
  std::string string;
  std::vector<Json> array;
  std::map<std::string, Json> object;

  const Json &operator[](const std::string &key) const {
    static const Json null;
    auto it = object.find(key);
    return it == object.end() ? null : it->second;
  }
};

class JsonParser {
public:
  explicit JsonParser(const std::string &text) : s_(text) {}
  Json parse() {
    Json v = value();
    skip();
    if (i_ != s_.size())
      fail("trailing characters");
    return v;
  }

private:
  [[noreturn]] void fail(const std::string &what) const {
    throw std::runtime_error("JSON: " + what + " at byte " + std::to_string(i_));
  }
  void skip() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_])))
      ++i_;
  }
  bool eat(char c) {
    skip();
    if (i_ < s_.size() && s_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!eat(c))
      fail(std::string("expected '") + c + "'");
  }
  bool word(const char *w) {
    size_t n = std::char_traits<char>::length(w);
    if (s_.compare(i_, n, w) == 0) {
      i_ += n;
      return true;
    }
    return false;
  }
  std::string str() {
    expect('"');
    std::string out;
    while (i_ < s_.size() && s_[i_] != '"') {
      if (s_[i_] == '\\') {
        ++i_;
        if (i_ >= s_.size())
          break;
        char c = s_[i_];
        out += c == 'n' ? '\n' : c == 't' ? '\t' : c;
        if (c == 'u')
          i_ += 4; // names here are ASCII; an escaped code point is dropped
      } else {
        out += s_[i_];
      }
      ++i_;
    }
    if (i_ >= s_.size())
      fail("unterminated string");
    ++i_;
    return out;
  }
  Json value() {
    skip();
    if (i_ >= s_.size())
      fail("unexpected end");
    Json v;
    char c = s_[i_];
    if (c == '{') {
      v.kind = Json::Object;
      ++i_;
      if (eat('}'))
        return v;
      do {
        skip();
        std::string key = str();
        expect(':');
        v.object[key] = value();
      } while (eat(','));
      expect('}');
    } else if (c == '[') {
      v.kind = Json::Array;
      ++i_;
      if (eat(']'))
        return v;
      do {
        v.array.push_back(value());
      } while (eat(','));
      expect(']');
    } else if (c == '"') {
      v.kind = Json::String;
      v.string = str();
    } else if (word("null")) {
      v.kind = Json::Null;
    } else if (word("true")) {
      v.kind = Json::Bool;
      v.boolean = true;
    } else if (word("false")) {
      v.kind = Json::Bool;
    } else {
      const char *start = s_.c_str() + i_;
      char *end = nullptr;
      v.number = std::strtod(start, &end);
      if (end == start)
        fail("expected a value");
      v.kind = Json::Number;
      i_ += end - start;
    }
    return v;
  }
  const std::string &s_;
  size_t i_ = 0;
};

// ---------------------------------------------------------------- the case

struct Side {
  PointVector points;
  VectorVector normals; // empty: a position-only side
  DoubleVector t;       // chord-length parameters on [0, 1]
};

struct Case {
  std::string name;
  std::vector<Side> sides;
  Json truth;
};

static Vector3D vec3(const Json &v, const std::string &where) {
  if (v.kind != Json::Array || v.array.size() != 3)
    throw std::runtime_error(where + ": expected three numbers");
  double c[3];
  for (int k = 0; k < 3; ++k) {
    if (v.array[k].kind != Json::Number || !std::isfinite(v.array[k].number))
      throw std::runtime_error(where + ": expected three finite numbers");
    c[k] = v.array[k].number;
  }
  return Vector3D(c[0], c[1], c[2]);
}

static Case readCase(const std::string &file) {
  std::ifstream in(file);
  if (!in)
    throw std::runtime_error(file + ": cannot be read");
  std::stringstream ss;
  ss << in.rdbuf();
  Json j;
  try {
    j = JsonParser(ss.str()).parse();
  } catch (const std::exception &e) {
    throw std::runtime_error(file + ": " + e.what());
  }
  Case c;
  c.name = j["name"].kind == Json::String ? j["name"].string : file;
  const Json &sides = j["sides"];
  if (sides.kind != Json::Array || sides.array.size() < 3 || sides.array.size() > 8)
    throw std::runtime_error(file + ": \"sides\" must be an array of 3 to 8 sides");
  for (size_t i = 0; i < sides.array.size(); ++i) {
    std::string where = file + ": sides[" + std::to_string(i) + "]";
    const Json &s = sides.array[i];
    Side side;
    const Json &pts = s["points"];
    if (pts.kind != Json::Array || pts.array.size() < 4)
      throw std::runtime_error(where + ".points: expected at least 4 points");
    for (size_t k = 0; k < pts.array.size(); ++k)
      side.points.push_back(vec3(pts.array[k], where + ".points[" + std::to_string(k) + "]"));
    const Json &ns = s["normals"];
    if (ns.kind == Json::Array) {
      if (ns.array.size() != side.points.size())
        throw std::runtime_error(where + ".normals: not one per point");
      for (size_t k = 0; k < ns.array.size(); ++k)
        side.normals.push_back(vec3(ns.array[k], where + ".normals[" + std::to_string(k) + "]"));
    } else if (ns.kind != Json::Null) {
      throw std::runtime_error(where + ".normals: expected an array or null");
    }
    side.t.push_back(0.0);
    for (size_t k = 1; k < side.points.size(); ++k) {
      double chord = (side.points[k] - side.points[k - 1]).norm();
      if (!(chord > 0.0))
        throw std::runtime_error(where + ".points[" + std::to_string(k) +
                                 "]: repeats the point before it");
      side.t.push_back(side.t.back() + chord);
    }
    double total = side.t.back();
    for (double &t : side.t)
      t /= total;
    c.sides.push_back(side);
  }
  for (size_t i = 0; i < c.sides.size(); ++i) {
    const Side &a = c.sides[i], &b = c.sides[(i + 1) % c.sides.size()];
    double gap = (a.points.back() - b.points.front()).norm();
    if (gap > 1e-9)
      throw std::runtime_error(file + ": corner " + std::to_string((i + 1) % c.sides.size()) +
                               ": sides do not meet (gap " + std::to_string(gap) + ")");
  }
  c.truth = j["truth"];
  return c;
}

static double truthDistance(const Json &truth, const Point3D &x) {
  const std::string &type = truth["type"].string;
  if (type == "sphere")
    return std::abs((x - vec3(truth["center"], "truth.center")).norm() - truth["radius"].number);
  if (type == "plane")
    return std::abs((x - vec3(truth["point"], "truth.point")) *
                    vec3(truth["normal"], "truth.normal").normalized());
  if (type == "cylinder") {
    Vector3D d = vec3(truth["axis_dir"], "truth.axis_dir").normalized();
    Vector3D r = x - vec3(truth["axis_point"], "truth.axis_point");
    return std::abs((r - d * (r * d)).norm() - truth["radius"].number);
  }
  return NAN;
}

// ---------------------------------------------------------------- the curves

// A cubic spline through p at parameters t (0 = t[0] < ... < t[n-1] = 1), clamped at each end
// to the slope of the cubic through the four nearest points.
class Clamped {
public:
  Clamped(const PointVector &p, const DoubleVector &t) : t_(t), p_(p), m_(p.size()) {
    size_t n = p.size();
    auto slope = [&](std::array<size_t, 4> idx, size_t at) {
      Vector3D d(0, 0, 0);
      for (size_t j : idx) {
        double w = 0;
        for (size_t k : idx) {
          if (k == j)
            continue;
          double prod = 1.0 / (t[j] - t[k]);
          for (size_t l : idx)
            if (l != j && l != k)
              prod *= (t[at] - t[l]) / (t[j] - t[l]);
          w += prod;
        }
        d += p[j] * w;
      }
      return d;
    };
    Vector3D d0 = slope({0, 1, 2, 3}, 0), d1 = slope({n - 4, n - 3, n - 2, n - 1}, n - 1);
    DoubleVector a(n, 0.0), b(n, 1.0), c(n, 0.0);
    VectorVector r(n);
    double h0 = t[1] - t[0], hn = t[n - 1] - t[n - 2];
    b[0] = 2 * h0;
    c[0] = h0;
    r[0] = ((p[1] - p[0]) / h0 - d0) * 6.0;
    a[n - 1] = hn;
    b[n - 1] = 2 * hn;
    r[n - 1] = (d1 - (p[n - 1] - p[n - 2]) / hn) * 6.0;
    for (size_t i = 1; i + 1 < n; ++i) {
      double ha = t[i] - t[i - 1], hb = t[i + 1] - t[i];
      a[i] = ha;
      b[i] = 2 * (ha + hb);
      c[i] = hb;
      r[i] = ((p[i + 1] - p[i]) / hb - (p[i] - p[i - 1]) / ha) * 6.0;
    }
    for (size_t i = 1; i < n; ++i) {
      double w = a[i] / b[i - 1];
      b[i] -= w * c[i - 1];
      r[i] -= r[i - 1] * w;
    }
    m_[n - 1] = r[n - 1] / b[n - 1];
    for (size_t i = n - 1; i-- > 0;)
      m_[i] = (r[i] - m_[i + 1] * c[i]) / b[i];
  }

  // Value and derivatives up to nr_der at s.
  void jet(double s, size_t nr_der, VectorVector &der) const {
    size_t n = t_.size();
    size_t i = std::upper_bound(t_.begin(), t_.end(), s) - t_.begin();
    i = std::clamp<size_t>(i, 1, n - 1) - 1;
    double h = t_[i + 1] - t_[i], x = s - t_[i];
    const Vector3D &p0 = p_[i], &p1 = p_[i + 1], &m0 = m_[i], &m1 = m_[i + 1];
    Vector3D sl = (p1 - p0) / h - (m0 * 2.0 + m1) * (h / 6.0);
    der.resize(nr_der + 1);
    for (size_t k = 0; k <= nr_der; ++k) {
      switch (k) {
      case 0: der[k] = p0 + sl * x + m0 * (x * x / 2) + (m1 - m0) * (x * x * x / (6 * h)); break;
      case 1: der[k] = sl + m0 * x + (m1 - m0) * (x * x / (2 * h)); break;
      case 2: der[k] = m0 + (m1 - m0) * (x / h); break;
      case 3: der[k] = (m1 - m0) / h; break;
      default: der[k] = Vector3D(0, 0, 0);
      }
    }
  }

  // Arc length from a to b: 5-point Gauss-Legendre on every knot interval (the curve is a
  // cubic there), as the library does for its own B-spline curves (4 points a knot interval).
  double arcLength(double a, double b) const {
    static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                0.5384693101056831, 0.9061798459386640};
    static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                0.4786286704993665, 0.2369268850561891};
    double sign = 1;
    if (b < a) {
      std::swap(a, b);
      sign = -1;
    }
    double sum = 0;
    VectorVector der;
    size_t i = std::upper_bound(t_.begin(), t_.end(), a) - t_.begin();
    i = std::clamp<size_t>(i, 1, t_.size() - 1) - 1;
    for (; i + 1 < t_.size() && t_[i] < b; ++i) {
      double lo = std::max(a, t_[i]), hi = std::min(b, t_[i + 1]);
      if (hi <= lo)
        continue;
      for (int q = 0; q < 5; ++q) {
        jet((lo + hi) / 2 + (hi - lo) / 2 * x[q], 1, der);
        sum += w[q] * der[1].norm() * (hi - lo) / 2;
      }
    }
    return sign * sum;
  }

private:
  DoubleVector t_;
  PointVector p_;
  VectorVector m_;
};

// The library's curve interface over a clamped spline. reverse() flips the parameter; the
// driver refuses a loop the library reverses (the fences are functions of the case's
// parameter), which cannot happen for cases written in loop order.
class SplineCurve : public Curve {
public:
  explicit SplineCurve(std::shared_ptr<const Clamped> c) : c_(std::move(c)) {}
  Point3D eval(double u) const override {
    VectorVector der;
    return eval(u, 0, der);
  }
  Point3D eval(double u, size_t nr_der, VectorVector &der) const override {
    c_->jet(reversed_ ? 1.0 - u : u, nr_der, der);
    if (reversed_)
      for (size_t k = 1; k < der.size(); k += 2)
        der[k] = -der[k];
    return der[0];
  }
  void reverse() override { reversed_ = !reversed_; }
  double arcLength(double from, double to) const override {
    return reversed_ ? c_->arcLength(1.0 - to, 1.0 - from) : c_->arcLength(from, to);
  }
  bool reversed() const { return reversed_; }

private:
  std::shared_ptr<const Clamped> c_;
  bool reversed_ = false;
};

// ---------------------------------------------------------------- the surfaces

static std::shared_ptr<Surface> newSurface(const std::string &type) {
  if (type == "sb") return std::make_shared<SurfaceSideBased>();
  if (type == "cb") return std::make_shared<SurfaceCornerBased>();
  if (type == "gc") return std::make_shared<SurfaceGeneralizedCoons>();
  if (type == "cr") return std::make_shared<SurfaceCompositeRibbon>();
  if (type == "mp") return std::make_shared<SurfaceMidpoint>();
  if (type == "mc") return std::make_shared<SurfaceMidpointCoons>();
  if (type == "el") return std::make_shared<SurfaceElastic>();
  if (type == "ha") return std::make_shared<SurfaceHarmonic>();
  if (type == "bh") return std::make_shared<SurfaceBiharmonic>();
  return nullptr;
}

static bool discrete(const std::string &type) { return type == "ha" || type == "bh"; }

struct Built {
  std::shared_ptr<Surface> surface;
  std::vector<std::shared_ptr<SplineCurve>> curves;
};

// The normal fence of side i: the clamped spline through the case's normals, normalised. With
// `corner` fences it is also made to agree with the curves at the corners: the library's
// corner data come from the curves' end tangents (the corner normal is the cross product of
// the two sides' tangents there), and a fence whose corner normal is not perpendicular to the
// neighbouring side's end tangent -- the case's normals are exact, the spline's tangents are
// O(h^3) off -- leaves the corner-blended patches (cb, gc, cr, mp, mc) off their boundary by
// about that much. The correction adds the corner mismatches, blended linearly in s, and
// projects the result perpendicular to the side's own tangent before normalising.
static std::shared_ptr<NormalFence> fence(size_t i, const Built &b,
                                          std::shared_ptr<const Clamped> f, bool corner) {
  if (!corner)
    return std::make_shared<NormalFence>([f](double s) {
      VectorVector der;
      f->jet(s, 0, der);
      return der[0].normalized();
    });
  size_t n = b.curves.size();
  std::shared_ptr<Curve> prev = b.curves[(i + n - 1) % n], curve = b.curves[i],
                         next = b.curves[(i + 1) % n];
  VectorVector a, c;
  f->jet(0.0, 0, a);
  Vector3D n0 = a[0].normalized();
  f->jet(1.0, 0, a);
  Vector3D n1 = a[0].normalized();
  prev->eval(1.0, 1, a);
  curve->eval(0.0, 1, c);
  Vector3D c0 = (a[1] ^ c[1]).normalized();
  curve->eval(1.0, 1, a);
  next->eval(0.0, 1, c);
  Vector3D c1 = (a[1] ^ c[1]).normalized();
  if (c0 * n0 < 0)
    c0 = -c0;
  if (c1 * n1 < 0)
    c1 = -c1;
  Vector3D d0 = c0 - n0, d1 = c1 - n1;
  return std::make_shared<NormalFence>([f, curve, d0, d1](double s) {
    VectorVector der, tan;
    f->jet(s, 0, der);
    Vector3D m = der[0].normalized() + d0 * (1 - s) + d1 * s;
    curve->eval(s, 1, tan);
    Vector3D t = tan[1].normalized();
    return (m - t * (m * t)).normalized();
  });
}

static Built build(const std::string &type, const Case &c,
                   const std::vector<std::shared_ptr<const Clamped>> &splines,
                   const std::vector<std::shared_ptr<const Clamped>> &fences, bool corner) {
  Built b;
  b.surface = newSurface(type);
  CurveVector curves;
  for (auto &s : splines) {
    b.curves.push_back(std::make_shared<SplineCurve>(s));
    curves.push_back(b.curves.back());
  }
  b.surface->setCurves(curves);
  b.surface->setupLoop();
  for (size_t i = 0; i < c.sides.size(); ++i)
    if (fences[i])
      b.surface->overrideNormalFence(i, fence(i, b, fences[i], corner));
  b.surface->update();
  return b;
}

static double median(DoubleVector v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

static double seconds(const std::function<void()> &f) {
  auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

static double pointSegment(const Point3D &p, const Point3D &a, const Point3D &b) {
  Vector3D d = b - a;
  double l2 = d.normSqr();
  double x = l2 > 0 ? std::clamp((p - a) * d / l2, 0.0, 1.0) : 0.0;
  return (p - (a + d * x)).norm();
}

static std::string num(double x) {
  if (!std::isfinite(x))
    return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", x);
  return buf;
}

static void usage() {
  std::cerr << "usage: salvi_fill CASE.json [--repeat K] [--resolution R] [--types a,b,...]\n"
               "                  [--fences corner|raw]\n"
               "types: sb cb gc cr mp mc el ha bh\n";
  std::exit(2);
}

int main(int argc, char **argv) {
  std::string file;
  int repeat = 7;
  size_t resolution = 40;
  std::vector<std::string> types = {"sb", "cb", "gc", "cr", "mp", "mc", "el", "ha", "bh"};
  bool corner = true;
  for (int a = 1; a < argc; ++a) {
    std::string arg = argv[a];
    if ((arg == "--repeat" || arg == "--resolution" || arg == "--types" || arg == "--fences") &&
        a + 1 < argc) {
      std::string val = argv[++a];
      if (arg == "--fences") {
        if (val != "corner" && val != "raw")
          usage();
        corner = val == "corner";
      } else if (arg == "--types") {
        types.clear();
        std::stringstream ss(val);
        std::string t;
        while (std::getline(ss, t, ','))
          if (!newSurface(t)) {
            std::cerr << "salvi_fill: unknown surface type '" << t << "'\n";
            usage();
          } else {
            types.push_back(t);
          }
      } else {
        char *end = nullptr;
        long k = std::strtol(val.c_str(), &end, 10);
        if (*end || k < 1 || k > 100000)
          usage();
        if (arg == "--repeat")
          repeat = int(k);
        else
          resolution = size_t(k);
      }
    } else if (!arg.empty() && arg[0] != '-' && file.empty()) {
      file = arg;
    } else {
      usage();
    }
  }
  if (file.empty())
    usage();

  Case c;
  try {
    c = readCase(file);
  } catch (const std::exception &e) {
    std::cerr << "salvi_fill: " << e.what() << "\n";
    return 1;
  }
  size_t n = c.sides.size();
  std::vector<std::shared_ptr<const Clamped>> splines, fences;
  for (auto &s : c.sides) {
    splines.push_back(std::make_shared<Clamped>(s.points, s.t));
    fences.push_back(s.normals.empty() ? nullptr : std::make_shared<Clamped>(s.normals, s.t));
  }

  for (const auto &type : types) {
    std::ostringstream line;
    line << "{\"case\": \"" << c.name << "\", \"type\": \"" << type << "\"";
    try {
      Built b;
      DoubleVector build_t, update_t, mesh_t;
      TriMesh mesh;
      for (int r = 0; r < repeat; ++r) {
        build_t.push_back(seconds([&] {
          b = build(type, c, splines, fences, corner);
          if (discrete(type))
            mesh = b.surface->eval(resolution);
        }));
      }
      for (auto &curve : b.curves)
        if (curve->reversed())
          throw std::runtime_error("the library reversed a side: the loop is not in order");
      for (int r = 0; r < repeat; ++r)
        update_t.push_back(seconds([&] { b.surface->update(); }));
      for (int r = 0; r < repeat; ++r)
        mesh_t.push_back(seconds([&] { mesh = b.surface->eval(resolution); }));

      double boundary = 0, g1 = 0, g1_change = 0, g1_t = NAN;
      size_t g1_side = 0;
      bool has_g1 = false;
      auto domain = b.surface->domain();
      if (discrete(type)) {
        // The mesh's boundary edges: those of one triangle only.
        std::map<std::pair<size_t, size_t>, int> count;
        for (auto &t : mesh.triangles())
          for (int k = 0; k < 3; ++k) {
            size_t u = t[k], v = t[(k + 1) % 3];
            count[{std::min(u, v), std::max(u, v)}]++;
          }
        std::vector<std::pair<size_t, size_t>> edges;
        for (auto &[e, k] : count)
          if (k == 1)
            edges.push_back(e);
        for (auto &s : c.sides)
          for (auto &p : s.points) {
            double best = INFINITY;
            for (auto &[u, v] : edges)
              best = std::min(best, pointSegment(p, mesh[u], mesh[v]));
            boundary = std::max(boundary, best);
          }
      } else {
        const Surface &S = *b.surface;
        auto normal_at = [&](size_t i, double s, double h) {
          const Point2DVector &V = domain->vertices();
          Vector2D e = V[i] - V[(i + n - 1) % n];
          Vector2D w(-e[1], e[0]);
          if ((domain->center() - V[i]) * w < 0)
            w = -w;
          // Steps relative to the edge's length (the side-based domain is as large as the loop).
          h *= e.norm();
          e = e / e.norm();
          w = w / w.norm();
          Point2D p = domain->edgePoint(i, s);
          Vector3D su = (S.eval(p + e * h) - S.eval(p - e * h)) / (2 * h);
          Vector3D sw = (S.eval(p) * -3.0 + S.eval(p + w * h) * 4.0 - S.eval(p + w * (2 * h))) /
                        (2 * h);
          return (su ^ sw).normalized();
        };
        auto angle = [](const Vector3D &a, const Vector3D &m) {
          return std::atan2((a ^ m).norm(), std::abs(a * m));
        };
        for (size_t i = 0; i < n; ++i) {
          const Side &side = c.sides[i];
          for (size_t j = 0; j < side.points.size(); ++j) {
            Point3D x = S.eval(domain->edgePoint(i, side.t[j]));
            boundary = std::max(boundary, (x - side.points[j]).norm());
            if (side.normals.empty() || j == 0 || j + 1 == side.points.size())
              continue;
            has_g1 = true;
            double a1 = angle(normal_at(i, side.t[j], 3e-5), side.normals[j]);
            double a2 = angle(normal_at(i, side.t[j], 6e-5), side.normals[j]);
            if (a1 > g1) {
              g1 = a1;
              g1_side = i;
              g1_t = side.t[j];
            }
            g1_change = std::max(g1_change, std::abs(a1 - a2));
          }
        }
      }
      double worst = 0, sum = 0;
      for (auto &p : mesh.points()) {
        double d = truthDistance(c.truth, p);
        worst = std::max(worst, d);
        sum += d * d;
      }
      line << ", \"sides\": " << n << ", \"boundary\": " << num(boundary)
           << ", \"g1\": " << (has_g1 ? num(g1) : "null")
           << ", \"g1_fd_change\": " << (has_g1 ? num(g1_change) : "null")
           << ", \"g1_side\": " << (has_g1 ? std::to_string(g1_side) : "null")
           << ", \"g1_t\": " << (has_g1 ? num(g1_t) : "null")
           << ", \"fences\": \"" << (corner ? "corner" : "raw") << "\""
           << ", \"truth_max\": " << num(worst)
           << ", \"truth_rms\": " << num(std::sqrt(sum / mesh.points().size()))
           << ", \"mesh_points\": " << mesh.points().size()
           << ", \"build_median_s\": " << num(median(build_t))
           << ", \"update_median_s\": " << num(median(update_t))
           << ", \"mesh_median_s\": " << num(median(mesh_t)) << "}";
    } catch (const std::exception &e) {
      line << ", \"error\": \"" << e.what() << "\"}";
    }
    std::cout << line.str() << std::endl;
  }
  return 0;
}
