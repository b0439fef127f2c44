#include "map_aided_fusion/map_io/map_loader.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <cstring>
#include <memory>
#include <set>
#include <mutex>
#include <sstream>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_vsi.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include "map_aided_fusion/core/parameters.hpp"
#include "map_aided_fusion/map_io/projection.hpp"

namespace map_aided_fusion {
namespace map_io {

namespace {

constexpr std::size_t kMaxReportMessages = 20;
constexpr double kFeetToMetres = 0.3048;
/// A `lanes` value above this is a tagging error (ignored).
constexpr long kMaxLanes = 64;
constexpr double kMaxLatitude = 90.0;
constexpr double kMaxLongitude = 180.0;
constexpr double kMetresPerKilometre = 1000.0;
/// Squared distance (m²) standing for "no data point on this side of the globe".
constexpr double kNoNearest = 1e300;
/// Vertices closer than this (map units) are merged.
constexpr double kDuplicateVertexTolerance = 1e-9;
/// Source coordinates beyond this magnitude are no place on Earth in any CRS (metres, feet or degrees);
/// PROJ can loop for a long time on them, so they never reach the transformation.
constexpr double kMaxSourceCoordinate = 1e9;
/// Bounds of origin_altitude, metres above the ellipsoid (deepest dry land to above the highest summit).
constexpr double kMinOriginAltitude = -1000.0;
constexpr double kMaxOriginAltitude = 10000.0;
/// Bounds of max_vertices_per_feature.
constexpr double kMinVerticesPerFeature = 3.0;
constexpr double kMaxVerticesPerFeature = 1e8;
constexpr double kFullTurnDegrees = 360.0;

using core::Point2;
using Ring = std::vector<Point2>;

struct RawPolygon
{
  Ring outer;
  std::vector<Ring> holes;
};

enum class Role
{
  kNone,
  kBuilding,
  kRoadArea,
  kRoadLine,
};

struct GdalCloser
{
  void operator()(GDALDataset* ds) const { GDALClose(ds); }
};

void registerGdal()
{
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

std::string lower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool endsWith(const std::string& s, const std::string& suffix)
{
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// "7", "7.5 m", "3,5", "24 ft" → metres; NaN when not a positive length.
double parseLength(const std::string& text)
{
  std::string s = text;
  std::replace(s.begin(), s.end(), ',', '.');
  const char* begin = s.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(v) || v <= 0.0) return std::nan("");
  std::string unit = lower(std::string(end));
  unit.erase(std::remove_if(unit.begin(), unit.end(), [](unsigned char c) { return std::isspace(c); }), unit.end());
  if (unit.empty() || unit == "m" || unit == "meters" || unit == "metres") return v;
  if (unit == "ft" || unit == "'" || unit == "feet") return v * kFeetToMetres;
  return std::nan("");
}

/// Positive integer count ("2", "2;3" takes the first); 0 when unknown.
int parseCount(const std::string& text)
{
  const char* begin = text.c_str();
  char* end = nullptr;
  const long v = std::strtol(begin, &end, 10);
  if (end == begin || v <= 0 || v > kMaxLanes) return 0;
  return static_cast<int>(v);
}

MapSourceKind kindFromExtension(const std::string& file)
{
  const std::string f = lower(file);
  if (endsWith(f, ".osm") || endsWith(f, ".pbf") || endsWith(f, ".osm.xml")) return MapSourceKind::kOsm;
  if (endsWith(f, ".geojson") || endsWith(f, ".json")) return MapSourceKind::kGeoJson;
  if (endsWith(f, ".shp")) return MapSourceKind::kShapefile;
  if (endsWith(f, ".gpkg")) return MapSourceKind::kGeoPackage;
  return MapSourceKind::kAuto;
}

std::string osmConfig(const MapLoadParams& p)
{
  const std::string common = "osm_id=yes\nosm_version=no\nosm_timestamp=no\nosm_uid=no\nosm_user=no\nosm_changeset=no\n";
  std::ostringstream c;
  // Closed ways are read as lines and made polygons here: GDAL reports missing nodes only for lines.
  c << "closed_ways_are_polygons=map_aided_fusion_no_key\n";
  c << "attribute_name_laundering=no\n";
  c << "[points]\n" << common << "attributes=name\n";
  c << "[lines]\n" << common << "attributes=name," << p.building_attribute << "," << p.building_height_attribute
    << "," << p.building_levels_attribute << "," << p.road_class_attribute << ","
    << p.road_width_attribute << "," << p.road_lanes_attribute << "," << p.road_area_attribute << ",area,"
    << p.road_tunnel_attribute << "\n";
  c << "[multipolygons]\n" << common << "attributes=name,type," << p.building_attribute << ","
    << p.building_height_attribute << "," << p.building_levels_attribute << "," << p.road_class_attribute << ","
    << p.road_area_attribute << ",area," << p.road_tunnel_attribute << "\n";
  c << "[multilinestrings]\n" << common << "attributes=name,type\n";
  c << "[other_relations]\n" << common << "attributes=name,type\n";
  return c.str();
}

/// A file in GDAL's in-memory file system, deleted on destruction.
class VsiMemFile
{
public:
  explicit VsiMemFile(const std::string& content)
  {
    static std::atomic<int> counter{ 0 };
    path_ = "/vsimem/map_aided_fusion_osmconf_" + std::to_string(counter++) + ".ini";
    VSILFILE* f = VSIFOpenL(path_.c_str(), "wb");
    if (f != nullptr)
    {
      VSIFWriteL(content.data(), 1, content.size(), f);
      VSIFCloseL(f);
    }
  }
  ~VsiMemFile() { VSIUnlink(path_.c_str()); }
  VsiMemFile(const VsiMemFile&) = delete;
  VsiMemFile& operator=(const VsiMemFile&) = delete;
  const std::string& path() const { return path_; }

private:
  std::string path_;
};

/// Collects GDAL's messages while loading instead of printing them.
class ErrorCapture
{
public:
  ErrorCapture()
  {
    const char* debug = CPLGetThreadLocalConfigOption("CPL_DEBUG", nullptr);
    if (debug != nullptr) saved_debug_ = debug;
    had_debug_ = debug != nullptr;
    // The OSM driver reports ways with missing nodes only as debug messages: count them.
    CPLSetThreadLocalConfigOption("CPL_DEBUG", "ON");
    CPLPushErrorHandlerEx(&ErrorCapture::handler, this);
  }
  ~ErrorCapture()
  {
    CPLPopErrorHandler();
    CPLSetThreadLocalConfigOption("CPL_DEBUG", had_debug_ ? saved_debug_.c_str() : nullptr);
  }
  ErrorCapture(const ErrorCapture&) = delete;
  ErrorCapture& operator=(const ErrorCapture&) = delete;
  const std::string& last() const { return last_; }
  /// Errors (CE_Failure or worse) reported by GDAL so far.
  std::size_t failures() const { return failures_; }
  /// Ids ("way/N") of ways the OSM driver dropped: fewer than 2 of their nodes in the file or the extract.
  const std::vector<std::string>& discardedWays() const { return discarded_ways_; }
  /// Ids ("relation/N") of relations the OSM driver ignored because member ways are missing from the extract.
  const std::vector<std::string>& incompleteRelations() const { return incomplete_relations_; }
  /// Ways the OSM driver shortened because some of their nodes are missing from the extract.
  bool truncated(long long way_id) const { return truncated_ways_.count(way_id) > 0; }

private:
  static void CPL_STDCALL handler(CPLErr level, CPLErrorNum, const char* msg)
  {
    auto* self = static_cast<ErrorCapture*>(CPLGetErrorHandlerUserData());
    if (self == nullptr || msg == nullptr) return;
    const std::string m(msg);
    if (level == CE_Debug)
    {
      long long id = 0;
      int got = 0, want = 0;
      const char* text = std::strstr(msg, "For way ");
      if (text != nullptr && std::sscanf(text, "For way %lld, got only %d nodes instead of %d", &id, &got, &want) == 3)
        self->truncated_ways_.insert(id);
      else if (m.find("Way ") != std::string::npos && m.find("Discarding it") != std::string::npos)
        self->remember(self->discarded_ways_, m, "Way ", "way/");
      else if (m.find("has missing ways") != std::string::npos)
        self->remember(self->incomplete_relations_, m, "Relation ", "relation/");
      return;
    }
    self->last_ = m;
    if (level >= CE_Failure) ++self->failures_;
  }
  std::string last_;
  std::string saved_debug_;
  bool had_debug_ = false;
  static void remember(std::vector<std::string>& ids, const std::string& m, const char* prefix, const char* kind)
  {
    const std::size_t at = m.find(prefix);
    long long id = 0;
    if (at != std::string::npos && std::sscanf(m.c_str() + at + std::strlen(prefix), "%lld", &id) == 1)
      ids.push_back(kind + std::to_string(id));
    else
      ids.push_back(std::string(kind) + "?");
  }

  std::vector<std::string> discarded_ways_;
  std::vector<std::string> incomplete_relations_;
  std::size_t failures_ = 0;
  std::set<long long> truncated_ways_;
};

class Loader
{
public:
  Loader(const MapLoadParams& p, MapLoadReport& r) : p_(p), r_(r) {}

  core::VectorMap run()
  {
    open();
    readFeatures();
    project();
    return std::move(out_);
  }

  /// The geometry path on features given in memory (no file, no driver): geometry checks, repair, projection.
  core::VectorMap run(const std::vector<SourceFeature>& features)
  {
    r_.driver = "memory";
    for (const SourceFeature& f : features)
    {
      ++r_.features_read;
      const bool line = f.kind == SourceFeature::Kind::kRoadLine;
      std::unique_ptr<OGRGeometry> g;
      if (line)
      {
        auto lines = std::make_unique<OGRMultiLineString>();
        for (const auto& part : f.parts)
        {
          auto ls = std::make_unique<OGRLineString>();
          for (const Point2& q : part) ls->addPoint(q.x, q.y);
          lines->addGeometryDirectly(ls.release());
        }
        g = std::move(lines);
      }
      else
      {
        auto poly = std::make_unique<OGRPolygon>();
        for (const auto& part : f.parts)
        {
          auto ring = std::make_unique<OGRLinearRing>();
          for (const Point2& q : part) ring->addPoint(q.x, q.y);
          poly->addRingDirectly(ring.release());
        }
        poly->closeRings();  // as every reader hands rings over
        g = std::move(poly);
      }
      if (g->IsEmpty())
      {
        ++r_.skipped_missing_nodes;
        note(f.id, "no geometry");
        continue;
      }
      addGeometry(f.id, line ? Role::kRoadLine : f.kind == SourceFeature::Kind::kBuilding ? Role::kBuilding :
                                                                                            Role::kRoadArea,
                  g.get(), nullptr, f.height, f.width, f.road_class);
    }
    project();
    return std::move(out_);
  }

private:
  struct PendingBuilding
  {
    RawPolygon polygon;
    double height;
    std::string id;
  };
  struct PendingLine
  {
    Ring points;
    double width;
    std::string road_class;
    std::string id;
  };

  [[noreturn]] void fail(const std::string& cause) const
  {
    throw MapLoadError("map file '" + p_.file + "': " + cause);
  }

  void note(const std::string& id, const std::string& why)
  {
    if (r_.messages.size() < kMaxReportMessages) r_.messages.push_back(id + ": " + why);
  }

  void open()
  {
    std::error_code ec;
    // GDAL's virtual file systems (/vsizip/, /vsimem/, ...) are paths too.
    VSIStatBufL stat;
    const bool virtual_path = p_.file.rfind("/vsi", 0) == 0;
    if (virtual_path ? VSIStatL(p_.file.c_str(), &stat) != 0 : !std::filesystem::exists(p_.file, ec))
      fail("file does not exist");
    kind_ = p_.source == MapSourceKind::kAuto ? kindFromExtension(p_.file) : p_.source;
    std::vector<const char*> drivers;
    std::vector<std::string> options;
    switch (kind_)
    {
      case MapSourceKind::kOsm:
        drivers = { "OSM" };
        osmconf_ = std::make_unique<VsiMemFile>(osmConfig(p_));
        options.push_back("CONFIG_FILE=" + osmconf_->path());
        break;
      case MapSourceKind::kGeoJson: drivers = { "GeoJSON", "GeoJSONSeq" }; break;
      case MapSourceKind::kShapefile: drivers = { "ESRI Shapefile" }; break;
      case MapSourceKind::kGeoPackage: drivers = { "GPKG" }; break;
      case MapSourceKind::kAuto: break;
    }
    if (!drivers.empty()) drivers.push_back(nullptr);
    std::vector<const char*> opts;
    for (const auto& o : options) opts.push_back(o.c_str());
    opts.push_back(nullptr);
    registerGdal();
    CPLErrorReset();
    ds_.reset(static_cast<GDALDataset*>(GDALOpenEx(p_.file.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY,
                                                   drivers.empty() ? nullptr : drivers.data(), opts.data(),
                                                   nullptr)));
    if (!ds_)
    {
      std::string why = errors_.last().empty() ? std::string("no GDAL vector driver can read it") : errors_.last();
      fail("cannot be read as " + toString(kind_) + " (" + why + ")");
    }
    r_.driver = ds_->GetDriverName();
    if (kind_ == MapSourceKind::kAuto && r_.driver == std::string("OSM")) kind_ = MapSourceKind::kOsm;
  }

  /// Coordinate transformation of a layer to WGS84 (longitude, latitude); null when none is needed.
  OGRCoordinateTransformation* transformFor(OGRLayer* layer)
  {
    if (p_.metric) return nullptr;
    auto it = transforms_.find(layer);
    if (it != transforms_.end()) return it->second.get();
    std::unique_ptr<OGRCoordinateTransformation> ct;
    const OGRSpatialReference* src = layer->GetSpatialRef();
    if (src != nullptr)
    {
      OGRSpatialReference wgs84;
      wgs84.SetWellKnownGeogCS("WGS84");
      wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
      OGRSpatialReference source(*src);
      source.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
      if (!(source.IsGeographic() && source.IsSameGeogCS(&wgs84)))
      {
        ct.reset(OGRCreateCoordinateTransformation(&source, &wgs84));
        if (!ct) fail("cannot transform the CRS of layer '" + std::string(layer->GetName()) + "' to WGS84");
      }
    }
    OGRCoordinateTransformation* raw = ct.get();
    transforms_.emplace(layer, std::move(ct));
    return raw;
  }

  static bool fieldSet(const OGRFeature& f, int idx) { return idx >= 0 && f.IsFieldSetAndNotNull(idx); }

  std::string field(const OGRFeature& f, const std::string& name) const
  {
    const int idx = f.GetFieldIndex(name.c_str());
    return fieldSet(f, idx) ? std::string(f.GetFieldAsString(idx)) : std::string();
  }

  bool isDrivable(const std::string& cls) const
  {
    for (const auto& c : p_.drivable_classes)
      if (c == "*" || c == cls) return true;
    return false;
  }

  bool isTunnel(const OGRFeature& f) const
  {
    const std::string t = field(f, p_.road_tunnel_attribute);
    return !t.empty() && t != "no" && t != "building_passage";
  }

  std::string featureId(OGRLayer* layer, const OGRFeature& f) const
  {
    if (kind_ == MapSourceKind::kOsm)
    {
      const std::string way = field(f, "osm_way_id");
      if (!way.empty()) return "way/" + way;
      const std::string id = field(f, "osm_id");
      if (!id.empty()) return (std::string(layer->GetName()) == "multipolygons" ? "relation/" : "way/") + id;
    }
    return std::string(layer->GetName()) + "/" + std::to_string(f.GetFID());
  }

  static bool isPolygonal(OGRwkbGeometryType t)
  {
    t = wkbFlatten(t);
    return t == wkbPolygon || t == wkbMultiPolygon || t == wkbCurvePolygon || t == wkbMultiSurface;
  }
  static bool isLinear(OGRwkbGeometryType t)
  {
    t = wkbFlatten(t);
    return t == wkbLineString || t == wkbMultiLineString || t == wkbCircularString || t == wkbCompoundCurve ||
           t == wkbMultiCurve;
  }

  Role roleOf(OGRLayer* layer, const OGRFeature& f, OGRwkbGeometryType type) const
  {
    const std::string lname = layer->GetName();
    const bool polygonal = isPolygonal(type);
    const bool linear = isLinear(type);
    if (!p_.building_layer.empty() && lname == p_.building_layer) return Role::kBuilding;
    if (!p_.road_area_layer.empty() && lname == p_.road_area_layer) return Role::kRoadArea;
    if (!p_.road_layer.empty() && lname == p_.road_layer)
    {
      const int idx = f.GetFieldIndex(p_.road_class_attribute.c_str());
      if (idx >= 0 && !isDrivable(field(f, p_.road_class_attribute))) return Role::kNone;
      return polygonal ? Role::kRoadArea : Role::kRoadLine;
    }
    const std::string building = field(f, p_.building_attribute);
    if (!building.empty() && building != "no") return Role::kBuilding;
    const std::string area_class = field(f, p_.road_area_attribute);
    if (!area_class.empty()) return isDrivable(area_class) ? Role::kRoadArea : Role::kNone;
    const std::string cls = field(f, p_.road_class_attribute);
    if (!cls.empty() && isDrivable(cls))
    {
      if (polygonal && field(f, "area") == "yes") return Role::kRoadArea;
      if (linear) return Role::kRoadLine;
    }
    return Role::kNone;
  }

  /// Number of vertices of a geometry (all rings and parts).
  static std::size_t vertexCount(const OGRGeometry* g)
  {
    const OGRwkbGeometryType t = wkbFlatten(g->getGeometryType());
    if (t == wkbPolygon)
    {
      const OGRPolygon* p = g->toPolygon();
      std::size_t n = p->getExteriorRing() ? static_cast<std::size_t>(p->getExteriorRing()->getNumPoints()) : 0;
      for (int k = 0; k < p->getNumInteriorRings(); ++k)
        n += static_cast<std::size_t>(p->getInteriorRing(k)->getNumPoints());
      return n;
    }
    if (t == wkbLineString || t == wkbLinearRing) return static_cast<std::size_t>(g->toLineString()->getNumPoints());
    if (OGR_GT_IsSubClassOf(t, wkbGeometryCollection))
    {
      std::size_t n = 0;
      for (const OGRGeometry* part : *g->toGeometryCollection()) n += vertexCount(part);
      return n;
    }
    if (OGR_GT_IsCurve(t)) return static_cast<std::size_t>(g->toSimpleCurve() ? g->toSimpleCurve()->getNumPoints() : 0);
    return 0;
  }

  /// True when every vertex of @p g is finite (an envelope skips NaN: GEOS must never see one).
  static bool allFinite(const OGRGeometry* g)
  {
    const OGRwkbGeometryType t = wkbFlatten(g->getGeometryType());
    if (t == wkbPolygon)
    {
      const OGRPolygon* p = g->toPolygon();
      for (const OGRLinearRing* ring : *p)
        if (!allFinite(ring)) return false;
      return true;
    }
    if (OGR_GT_IsSubClassOf(t, wkbGeometryCollection))
    {
      for (const OGRGeometry* part : *g->toGeometryCollection())
        if (!allFinite(part)) return false;
      return true;
    }
    if (const OGRSimpleCurve* c = OGR_GT_IsCurve(t) ? dynamic_cast<const OGRSimpleCurve*>(g) : nullptr)
    {
      for (int i = 0; i < c->getNumPoints(); ++i)
        if (!std::isfinite(c->getX(i)) || !std::isfinite(c->getY(i))) return false;
      return true;
    }
    OGREnvelope env;
    g->getEnvelope(&env);
    return std::isfinite(env.MinX) && std::isfinite(env.MaxX) && std::isfinite(env.MinY) && std::isfinite(env.MaxY);
  }

  /// True when every coordinate of @p g is finite and within kMaxSourceCoordinate.
  static bool coordinatesInRange(const OGRGeometry* g)
  {
    if (!allFinite(g)) return false;
    OGREnvelope env;
    g->getEnvelope(&env);
    for (const double v : { env.MinX, env.MaxX, env.MinY, env.MaxY })
      if (!std::isfinite(v) || std::abs(v) > kMaxSourceCoordinate) return false;
    return true;
  }

  /// A copy of @p poly without the holes that are disjoint from its shell or enclose it (they would be
  /// "repaired" into extra polygons); @p dropped counts them.
  static std::unique_ptr<OGRPolygon> withoutStrayHoles(const OGRPolygon& poly, std::size_t& dropped)
  {
    auto out = std::make_unique<OGRPolygon>();
    const OGRLinearRing* ext = poly.getExteriorRing();
    if (ext == nullptr) return out;
    // addRing() copies the ring; the const_casts only meet its older signature.
    out->addRing(const_cast<OGRLinearRing*>(ext));
    if (poly.getNumInteriorRings() == 0) return out;
    OGRPolygon shell;
    shell.addRing(const_cast<OGRLinearRing*>(ext));
    for (int k = 0; k < poly.getNumInteriorRings(); ++k)
    {
      OGRPolygon hole;
      hole.addRing(const_cast<OGRLinearRing*>(poly.getInteriorRing(k)));
      if (!shell.Intersects(&hole) || hole.Contains(&shell))
      {
        ++dropped;
        continue;
      }
      out->addRing(const_cast<OGRLinearRing*>(poly.getInteriorRing(k)));
    }
    return out;
  }

  /// Appends the vertices of a ring (closing vertex and duplicates removed); false when degenerate.
  static bool ringPoints(const OGRLinearRing& ring, Ring& out)
  {
    out.clear();
    const int n = ring.getNumPoints();
    out.reserve(static_cast<std::size_t>(std::max(n, 0)));
    for (int i = 0; i < n; ++i)
    {
      const Point2 q{ ring.getX(i), ring.getY(i) };
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
      if (!out.empty() && std::abs(out.back().x - q.x) <= kDuplicateVertexTolerance &&
          std::abs(out.back().y - q.y) <= kDuplicateVertexTolerance)
        continue;
      out.push_back(q);
    }
    while (out.size() > 1 && std::abs(out.back().x - out.front().x) <= kDuplicateVertexTolerance &&
           std::abs(out.back().y - out.front().y) <= kDuplicateVertexTolerance)
      out.pop_back();
    return out.size() >= 3;
  }

  void collectPolygons(const OGRGeometry* g, std::vector<const OGRPolygon*>& out) const
  {
    const OGRwkbGeometryType t = wkbFlatten(g->getGeometryType());
    if (t == wkbPolygon)
      out.push_back(g->toPolygon());
    else if (t == wkbMultiPolygon || t == wkbGeometryCollection)
      for (const OGRGeometry* part : *g->toGeometryCollection()) collectPolygons(part, out);
  }

  void addPolygonal(const std::string& id, Role role, OGRGeometry* geometry, double height)
  {
    std::unique_ptr<OGRGeometry> linear;
    if (OGR_GT_IsNonLinear(geometry->getGeometryType()))
    {
      linear.reset(geometry->getLinearGeometry());
      if (!linear) return skipDegenerate(id, "curved geometry could not be linearised");
      geometry = linear.get();
    }
    std::vector<const OGRPolygon*> parts;
    collectPolygons(geometry, parts);
    if (parts.empty()) return skipDegenerate(id, "no polygon in the geometry");
    // Holes outside their shell or around it are dropped first: repairing them would invent polygons.
    OGRMultiPolygon cleaned;
    std::size_t dropped = 0;
    for (const OGRPolygon* part : parts) cleaned.addGeometryDirectly(withoutStrayHoles(*part, dropped).release());
    if (dropped > 0)
    {
      r_.dropped_holes += dropped;
      note(id, std::to_string(dropped) + " hole(s) outside their shell or enclosing it dropped");
    }
    std::unique_ptr<OGRGeometry> repaired;
    std::vector<const OGRPolygon*> polygons;
    if (p_.repair_invalid && !cleaned.IsValid())
    {
      repaired.reset(cleaned.MakeValid());
      if (repaired && !repaired->IsEmpty() && repaired->IsValid()) collectPolygons(repaired.get(), polygons);
      if (polygons.empty())
      {
        ++r_.skipped_invalid;
        note(id, "invalid polygon that could not be repaired");
        return;
      }
      ++r_.repaired_geometries;
    }
    else
      collectPolygons(&cleaned, polygons);
    if (polygons.empty()) return skipDegenerate(id, "no polygon in the geometry");
    bool any = false;
    for (const OGRPolygon* poly : polygons)
    {
      RawPolygon raw;
      const OGRLinearRing* ext = poly->getExteriorRing();
      if (ext == nullptr || !ringPoints(*ext, raw.outer)) continue;
      for (int k = 0; k < poly->getNumInteriorRings(); ++k)
      {
        Ring hole;
        if (ringPoints(*poly->getInteriorRing(k), hole)) raw.holes.push_back(std::move(hole));
      }
      any = true;
      if (role == Role::kBuilding)
        buildings_.push_back(PendingBuilding{ std::move(raw), height, id });
      else
        areas_.push_back(std::move(raw));
    }
    if (!any) skipDegenerate(id, "polygon with fewer than 3 distinct vertices");
  }

  /// A closed line string (first vertex = last, ≥ 4 vertices) as a polygon; null otherwise.
  static std::unique_ptr<OGRPolygon> closedLineAsPolygon(const OGRGeometry* g)
  {
    if (wkbFlatten(g->getGeometryType()) != wkbLineString) return nullptr;
    const OGRLineString* ls = g->toLineString();
    if (ls->getNumPoints() < 4 || !ls->get_IsClosed()) return nullptr;
    auto ring = std::make_unique<OGRLinearRing>();
    ring->addSubLineString(ls);
    auto poly = std::make_unique<OGRPolygon>();
    poly->addRingDirectly(ring.release());
    return poly;
  }

  void addLinear(const std::string& id, OGRGeometry* geometry, double width, const std::string& cls)
  {
    std::unique_ptr<OGRGeometry> linear;
    if (OGR_GT_IsNonLinear(geometry->getGeometryType()))
    {
      linear.reset(geometry->getLinearGeometry());
      if (!linear) return skipDegenerate(id, "curved geometry could not be linearised");
      geometry = linear.get();
    }
    std::vector<const OGRLineString*> parts;
    const OGRwkbGeometryType t = wkbFlatten(geometry->getGeometryType());
    if (t == wkbLineString)
      parts.push_back(geometry->toLineString());
    else if (t == wkbMultiLineString)
      for (const OGRGeometry* g : *geometry->toMultiLineString()) parts.push_back(g->toLineString());
    bool any = false;
    for (const OGRLineString* ls : parts)
    {
      Ring pts;
      bool finite = true;
      for (int i = 0; i < ls->getNumPoints(); ++i)
      {
        const Point2 q{ ls->getX(i), ls->getY(i) };
        if (!std::isfinite(q.x) || !std::isfinite(q.y)) finite = false;
        if (!pts.empty() && pts.back().x == q.x && pts.back().y == q.y) continue;
        pts.push_back(q);
      }
      if (!finite || pts.size() < 2) continue;
      any = true;
      lines_.push_back(PendingLine{ std::move(pts), width, cls, id });
    }
    if (!any) skipDegenerate(id, "line with fewer than 2 distinct vertices");
  }

  void skipDegenerate(const std::string& id, const std::string& why)
  {
    ++r_.skipped_degenerate;
    note(id, why);
  }

  double buildingHeight(const OGRFeature& f) const
  {
    const double h = parseLength(field(f, p_.building_height_attribute));
    if (std::isfinite(h)) return h;
    const std::string levels = field(f, p_.building_levels_attribute);
    std::string s = levels;
    std::replace(s.begin(), s.end(), ',', '.');
    const double n = std::strtod(s.c_str(), nullptr);
    return (std::isfinite(n) && n > 0.0) ? n * p_.level_height : 0.0;
  }

  double roadWidth(const OGRFeature& f, const std::string& cls) const
  {
    const double w = parseLength(field(f, p_.road_width_attribute));
    if (std::isfinite(w)) return w;
    const int lanes = parseCount(field(f, p_.road_lanes_attribute));
    if (lanes > 0) return lanes * p_.lane_width;
    const auto it = p_.road_class_widths.find(cls);
    return it != p_.road_class_widths.end() ? it->second : p_.default_road_width;
  }

  void readFeatures()
  {
    const std::size_t failures_before = errors_.failures();
    readAllFeatures();
    r_.read_errors = errors_.failures() - failures_before;
    if (r_.read_errors > 0)
    {
      if (buildings_.empty() && areas_.empty() && lines_.empty())
        fail("read error after " + std::to_string(r_.features_read) + " features: " + errors_.last());
      note("file", "read error (the map may be incomplete): " + errors_.last());
    }
  }

  void readAllFeatures()
  {
    OGRLayer* layer = nullptr;
    for (;;)
    {
      std::unique_ptr<OGRFeature> f(ds_->GetNextFeature(&layer, nullptr, nullptr, nullptr));
      if (!f) break;
      ++r_.features_read;
      OGRGeometry* g = f->GetGeometryRef();
      const OGRwkbGeometryType type = g != nullptr ? g->getGeometryType() : wkbNone;
      const Role role = roleOf(layer, *f, type);
      if (role == Role::kNone) continue;
      if (role != Role::kBuilding && p_.exclude_tunnels && isTunnel(*f))
      {
        ++r_.excluded_tunnels;
        continue;
      }
      const std::string id = featureId(layer, *f);
      if (g == nullptr || g->IsEmpty())
      {
        ++r_.skipped_missing_nodes;
        note(id, "no geometry (nodes missing from the extract?)");
        continue;
      }
      if (kind_ == MapSourceKind::kOsm && errors_.truncated(std::atoll(field(*f, "osm_id").c_str())) &&
          std::string(layer->GetName()) == "lines")
      {
        ++r_.skipped_missing_nodes;
        note(id, "nodes missing from the extract");
        continue;
      }
      const double height = role == Role::kBuilding ? buildingHeight(*f) : 0.0;
      std::string cls;
      double width = 0.0;
      if (role == Role::kRoadLine)
      {
        cls = field(*f, p_.road_class_attribute);
        width = roadWidth(*f, cls);
      }
      addGeometry(id, role, g, transformFor(layer), height, width, cls);
    }
    // Ways GDAL's OSM driver dropped because their nodes were missing (reported only through CPLDebug).
    for (const std::string& id : errors_.discardedWays())
    {
      ++r_.skipped_missing_nodes;
      note(id, "way (of any kind) dropped by the reader: fewer than 2 of its nodes in the file");
    }
    for (const std::string& id : errors_.incompleteRelations())
    {
      ++r_.skipped_incomplete_relations;
      note(id, "relation (of any kind) ignored by the reader: member ways missing from the extract");
    }
  }

  /// Range and size checks, transformation to WGS84 (@p ct, null when none), repair, then the pending lists.
  void addGeometry(const std::string& id, Role role, OGRGeometry* g, OGRCoordinateTransformation* ct, double height,
                   double width, const std::string& cls)
  {
    const OGRwkbGeometryType type = g->getGeometryType();
    if (!coordinatesInRange(g)) return skipDegenerate(id, "coordinates not finite or beyond 1e9 in the source CRS");
    if (const std::size_t vertices = vertexCount(g); vertices > static_cast<std::size_t>(p_.max_vertices_per_feature))
    {
      ++r_.skipped_too_many_vertices;
      note(id, std::to_string(vertices) + " vertices, more than max_vertices_per_feature = " +
                   std::to_string(p_.max_vertices_per_feature));
      return;
    }
    if (ct != nullptr && g->transform(ct) != OGRERR_NONE)
      return skipDegenerate(id, "coordinates cannot be transformed to WGS84");
    if (role == Role::kBuilding || role == Role::kRoadArea)
    {
      if (isPolygonal(type))
        addPolygonal(id, role, g, height);
      else if (std::unique_ptr<OGRPolygon> ring = closedLineAsPolygon(g))
        addPolygonal(id, role, ring.get(), height);
      else if (isLinear(type))
      {
        ++r_.skipped_unclosed;
        note(id, std::string(role == Role::kBuilding ? "building" : "road area") + " way is not a closed ring");
      }
    }
    else if (isLinear(type))
      addLinear(id, g, width, cls);
    else if (isPolygonal(type))
      addPolygonal(id, Role::kRoadArea, g, 0.0);
  }

  template <class F>
  void forEachPoint(F&& f)
  {
    for (auto& b : buildings_)
    {
      for (auto& q : b.polygon.outer) f(q);
      for (auto& h : b.polygon.holes)
        for (auto& q : h) f(q);
    }
    for (auto& a : areas_)
    {
      for (auto& q : a.outer) f(q);
      for (auto& h : a.holes)
        for (auto& q : h) f(q);
    }
    for (auto& l : lines_)
      for (auto& q : l.points) f(q);
  }

  void project()
  {
    if (buildings_.empty() && areas_.empty() && lines_.empty())
      fail("no usable building or road feature (" + std::to_string(r_.features_read) + " features read, " +
           std::to_string(r_.skipped_unclosed + r_.skipped_missing_nodes + r_.skipped_degenerate + r_.skipped_invalid) +
           " skipped)");
    double lat0 = p_.origin_latitude, lon0 = p_.origin_longitude;
    if (!p_.metric)
    {
      bool out_of_range = false;
      double min_lon = 1e300, max_lon = -1e300, min_lat = 1e300, max_lat = -1e300;
      forEachPoint([&](Point2& q) {
        if (std::abs(q.y) > kMaxLatitude || std::abs(q.x) > kMaxLongitude) out_of_range = true;
        min_lon = std::min(min_lon, q.x);
        max_lon = std::max(max_lon, q.x);
        min_lat = std::min(min_lat, q.y);
        max_lat = std::max(max_lat, q.y);
      });
      if (out_of_range)
        fail("coordinates are not longitude/latitude degrees (a metric CRS without its definition? set `metric` "
             "for map-frame coordinates)");
      if (!std::isfinite(lat0) || !std::isfinite(lon0))
      {
        lat0 = 0.5 * (min_lat + max_lat);
        lon0 = 0.5 * (min_lon + max_lon);
        if (max_lon - min_lon > 0.5 * kFullTurnDegrees)
        {
          // Data across the antimeridian: the centre of the longitudes east of it, taken modulo 360.
          double lo = 1e300, hi = -1e300;
          forEachPoint([&](Point2& q) {
            const double l = q.x < 0.0 ? q.x + kFullTurnDegrees : q.x;
            lo = std::min(lo, l);
            hi = std::max(hi, l);
          });
          lon0 = 0.5 * (lo + hi);
          if (lon0 > kMaxLongitude) lon0 -= kFullTurnDegrees;
        }
      }
      const LocalProjector proj(lat0, lon0, p_.origin_altitude);
      // A point far round the globe projects near the origin on the tangent plane (the antipode onto the
      // origin itself): a vertex whose straight-line distance is beyond max_origin_distance while its
      // horizontal distance is less than half of that is on the far side; it becomes NaN and its feature
      // is dropped as out of range below.
      forEachPoint([&](Point2& q) {
        double up = 0.0;
        const Point2 e = proj.forward(q.y, q.x, &up);
        const double horizontal = std::hypot(e.x, e.y);
        const double chord = std::hypot(horizontal, up);
        q = chord > p_.max_origin_distance && horizontal < 0.5 * chord ? Point2{ std::nan(""), std::nan("") } : e;
      });
    }
    r_.origin_latitude = p_.metric ? 0.0 : lat0;
    r_.origin_longitude = p_.metric ? 0.0 : lon0;
    r_.origin_altitude = p_.origin_altitude;

    const double max_d2 = p_.max_origin_distance * p_.max_origin_distance;
    double nearest2 = kNoNearest;
    auto nearFeature = [&](const Ring& ring, bool& near) {
      bool far_side = false;
      for (const auto& q : ring)
      {
        const double d2 = q.x * q.x + q.y * q.y;
        far_side = far_side || !std::isfinite(d2);
        if (!std::isfinite(d2)) continue;
        nearest2 = std::min(nearest2, d2);
        if (d2 <= max_d2) near = true;
      }
      if (far_side) near = false;
    };
    auto dropFar = [&](const std::string& id) {
      ++r_.skipped_out_of_range;
      note(id, "farther than max_origin_distance from the origin");
    };
    for (auto& b : buildings_)
    {
      bool near = false;
      nearFeature(b.polygon.outer, near);
      if (!near)
      {
        dropFar(b.id);
        continue;
      }
      core::Building out;
      out.footprint.outer = std::move(b.polygon.outer);
      out.footprint.holes = std::move(b.polygon.holes);
      out.height = b.height;
      out.id = std::move(b.id);
      out_.buildings.push_back(std::move(out));
    }
    for (auto& a : areas_)
    {
      bool near = false;
      nearFeature(a.outer, near);
      if (!near)
      {
        dropFar("road area");
        continue;
      }
      out_.road_areas.push_back(core::Polygon{ std::move(a.outer), std::move(a.holes) });
    }
    for (auto& l : lines_)
    {
      bool near = false;
      nearFeature(l.points, near);
      if (!near)
      {
        dropFar(l.id);
        continue;
      }
      core::RoadLine out;
      out.points = std::move(l.points);
      out.width = l.width;
      out.road_class = std::move(l.road_class);
      out.id = std::move(l.id);
      out_.road_lines.push_back(std::move(out));
    }
    if (out_.buildings.empty() && out_.road_areas.empty() && out_.road_lines.empty())
    {
      std::ostringstream why;
      why.precision(1);
      why << std::fixed << "the origin (" << r_.origin_latitude << ", " << r_.origin_longitude << ") is ";
      if (std::isfinite(nearest2) && nearest2 < kNoNearest)
        why << std::sqrt(nearest2) / kMetresPerKilometre << " km from the nearest data";
      else
        why << "on the other side of the globe from all the data (more than a quarter of the Earth away)";
      why << ", more than max_origin_distance = " << p_.max_origin_distance / kMetresPerKilometre << " km";
      fail(why.str());
    }
    r_.buildings = out_.buildings.size();
    r_.road_areas = out_.road_areas.size();
    r_.road_lines = out_.road_lines.size();
    r_.skipped_geometries = r_.skipped_unclosed + r_.skipped_missing_nodes + r_.skipped_incomplete_relations +
                            r_.skipped_degenerate + r_.skipped_invalid + r_.skipped_out_of_range +
                            r_.skipped_too_many_vertices;
    out_.skipped_geometries = r_.skipped_geometries;
  }

  const MapLoadParams& p_;
  MapLoadReport& r_;
  ErrorCapture errors_;
  MapSourceKind kind_ = MapSourceKind::kAuto;
  std::unique_ptr<VsiMemFile> osmconf_;
  std::unique_ptr<GDALDataset, GdalCloser> ds_;
  std::map<OGRLayer*, std::unique_ptr<OGRCoordinateTransformation>> transforms_;
  std::vector<PendingBuilding> buildings_;
  std::vector<RawPolygon> areas_;
  std::vector<PendingLine> lines_;
  core::VectorMap out_;
};

}  // namespace

MapSourceKind parseMapSourceKind(const std::string& name)
{
  const std::string n = lower(name);
  if (n == "auto" || n.empty()) return MapSourceKind::kAuto;
  if (n == "osm" || n == "pbf") return MapSourceKind::kOsm;
  if (n == "geojson" || n == "json") return MapSourceKind::kGeoJson;
  if (n == "shapefile" || n == "shp") return MapSourceKind::kShapefile;
  if (n == "gpkg" || n == "geopackage") return MapSourceKind::kGeoPackage;
  throw core::ParameterError("source", "unknown map source kind '" + name + "' (auto, osm, geojson, shapefile, gpkg)");
}

std::string toString(MapSourceKind kind)
{
  switch (kind)
  {
    case MapSourceKind::kAuto: return "auto";
    case MapSourceKind::kOsm: return "osm";
    case MapSourceKind::kGeoJson: return "geojson";
    case MapSourceKind::kShapefile: return "shapefile";
    case MapSourceKind::kGeoPackage: return "gpkg";
  }
  return "auto";
}

std::vector<std::string> defaultDrivableClasses()
{
  return { "motorway",      "trunk",          "primary",      "secondary",     "tertiary",
           "unclassified",  "residential",    "service",      "living_street", "motorway_link",
           "trunk_link",    "primary_link",   "secondary_link", "tertiary_link", "road" };
}

std::map<std::string, double> defaultRoadClassWidths()
{
  return { { "motorway", 14.0 },     { "trunk", 12.0 },       { "primary", 10.0 },       { "secondary", 9.0 },
           { "tertiary", 8.0 },      { "unclassified", 6.0 }, { "residential", 6.0 },    { "service", 4.0 },
           { "living_street", 5.0 }, { "motorway_link", 7.0 }, { "trunk_link", 7.0 },   { "primary_link", 6.5 },
           { "secondary_link", 6.0 }, { "tertiary_link", 6.0 }, { "road", 6.0 } };
}

void MapLoadParams::validate() const
{
  if (file.empty()) throw core::ParameterError("map_file", "no map file given");
  if (!metric)
  {
    for (const auto& [name, value] : { std::pair<const char*, double>{ "origin_latitude", origin_latitude },
                                       std::pair<const char*, double>{ "origin_longitude", origin_longitude } })
      if (std::isinf(value)) throw core::ParameterError(name, "must be finite degrees (NaN, or absent: automatic)");
    const bool auto_lat = std::isnan(origin_latitude), auto_lon = std::isnan(origin_longitude);
    if (auto_lat != auto_lon)
      throw core::ParameterError(auto_lat ? "origin_latitude" : "origin_longitude",
                                 std::string("is NaN (automatic) but ") +
                                     (auto_lat ? "origin_longitude" : "origin_latitude") +
                                     " is set: give both origin_latitude and origin_longitude, or neither");
    if (!auto_lat) core::requireInRange("origin_latitude", origin_latitude, -kMaxLatitude, kMaxLatitude);
    if (!auto_lon) core::requireInRange("origin_longitude", origin_longitude, -kMaxLongitude, kMaxLongitude);
  }
  core::requireInRange("origin_altitude", origin_altitude, kMinOriginAltitude, kMaxOriginAltitude);
  core::requireInRange("max_vertices_per_feature", static_cast<double>(max_vertices_per_feature),
                       kMinVerticesPerFeature, kMaxVerticesPerFeature);
  core::requirePositive("max_origin_distance", max_origin_distance);
  core::requirePositive("lane_width", lane_width);
  core::requirePositive("level_height", level_height);
  core::requirePositive("default_road_width", default_road_width);
  for (const auto& kv : road_class_widths) core::requirePositive("road_class_widths/" + kv.first, kv.second);
  if (building_attribute.empty() && building_layer.empty())
    throw core::ParameterError("building_attribute", "empty, and no building_layer either");
}

namespace {

/// Validates @p params, resets the report (@p report or a local one) and runs @p run on a Loader.
template <class Run>
core::VectorMap withLoader(const MapLoadParams& params, MapLoadReport* report, Run&& run)
{
  params.validate();
  MapLoadReport local;
  MapLoadReport& r = report != nullptr ? *report : local;
  r = MapLoadReport{};
  r.file = params.file;
  Loader loader(params, r);
  return run(loader);
}

}  // namespace

core::VectorMap loadVectorMap(const MapLoadParams& params, MapLoadReport* report)
{
  return withLoader(params, report, [](Loader& loader) { return loader.run(); });
}

core::VectorMap buildVectorMap(const std::vector<SourceFeature>& features, const MapLoadParams& params,
                               MapLoadReport* report)
{
  MapLoadParams p = params;
  if (p.file.empty()) p.file = "(in memory)";  // named in errors; nothing is opened
  return withLoader(p, report, [&](Loader& loader) { return loader.run(features); });
}

std::string summary(const MapLoadReport& r)
{
  std::ostringstream s;
  s.precision(7);
  s << r.file << " (" << r.driver << "), origin " << r.origin_latitude << ", " << r.origin_longitude << ": "
    << r.features_read << " features read; kept " << r.buildings << " buildings, " << r.road_areas
    << " road areas, " << r.road_lines << " road lines (" << r.excluded_tunnels << " tunnels left out); repaired " << r.repaired_geometries << "; skipped "
    << r.skipped_geometries << " (unclosed " << r.skipped_unclosed << ", missing nodes " << r.skipped_missing_nodes
    << ", incomplete relations " << r.skipped_incomplete_relations
    << ", degenerate " << r.skipped_degenerate << ", invalid " << r.skipped_invalid << ", out of range "
    << r.skipped_out_of_range << ", too many vertices " << r.skipped_too_many_vertices << "); holes dropped "
    << r.dropped_holes;
  if (r.read_errors > 0) s << "; " << r.read_errors << " read errors: the map may be incomplete";
  return s.str();
}

}  // namespace map_io
}  // namespace map_aided_fusion
