#include "evio/scenes/scene_description.h"

#include <filesystem>
#include <functional>
#include <set>

#include "evio/core/error.h"

namespace evio::scenes {

namespace {

using config::Document;

/// The node at a dotted field path below `node` ("albedo.size_m[1]"); an
/// undefined node when absent.
YAML::Node nodeAt(const YAML::Node& node, const std::string& field) {
  YAML::Node cur = node;
  std::size_t pos = 0;
  while (pos < field.size()) {
    std::size_t end = field.find_first_of(".[", pos);
    if (end == std::string::npos) end = field.size();
    const std::string key = field.substr(pos, end - pos);
    if (!key.empty()) {
      if (!cur.IsMap() || !cur[key].IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
      cur.reset(cur[key]);
    }
    if (end < field.size() && field[end] == '[') {
      const std::size_t close = field.find(']', end);
      if (close == std::string::npos) break;
      const std::size_t index = std::stoul(field.substr(end + 1, close - end - 1));
      if (!cur.IsSequence() || index >= cur.size()) break;
      cur.reset(cur[index]);
      pos = close + 1;
      if (pos < field.size() && field[pos] == '.') ++pos;
    } else {
      pos = end + 1;
    }
  }
  return cur;
}

/// Rethrows a validate() error "field: message" of the element at `path` with
/// the file and line of that field (or of the element when the field is absent).
[[noreturn]] void rethrowAt(const Document& doc, const YAML::Node& element, const std::string& path,
                            const Error& e) {
  const std::string msg = e.what();
  const auto colon = msg.find(": ");
  const std::string field = colon == std::string::npos ? std::string() : msg.substr(0, colon);
  YAML::Node at = field.empty() ? YAML::Node(YAML::NodeType::Undefined) : nodeAt(element, field);
  // Keep only the leading key path of the field for the lookup of its line.
  if (!at.IsDefined()) at.reset(element);
  throw Error(config::where(doc, at, path) + ": " + path + "." + msg);
}

/// Reports an unknown or missing `key` (a type tag) of the map `item` at
/// `path` before the item is read, so that the message is about the type and
/// not about its fields.
void checkTag(const Document& doc, const YAML::Node& item, const std::string& path, const std::string& key,
              const std::function<bool(const std::string&)>& known, const std::string& known_list,
              const std::string& what, bool required) {
  if (!item.IsDefined() || !item.IsMap()) return;  // the reader reports the shape
  const YAML::Node tag = item[key];
  if (!tag.IsDefined() || tag.IsNull()) {
    if (required)
      throw Error(config::where(doc, item, path) + ": " + path + "." + key + ": missing (known " + what +
                  "s: " + known_list + ")");
    return;
  }
  if (!tag.IsScalar() || !known(tag.Scalar()))
    throw Error(config::where(doc, tag, path + "." + key) + ": " + path + "." + key + ": unknown " + what + " '" +
                (tag.IsScalar() ? tag.Scalar() : std::string("?")) + "' (known: " + known_list + ")");
}

/// checkTag for every item of the list `list_name`.
void checkTags(const Document& doc, const YAML::Node& list, const std::string& list_name, const std::string& key,
               const std::function<bool(const std::string&)>& known, const std::string& known_list,
               const std::string& what, bool required) {
  if (!list.IsDefined() || !list.IsSequence()) return;
  for (std::size_t i = 0; i < list.size(); ++i)
    checkTag(doc, list[i], list_name + "[" + std::to_string(i) + "]", key, known, known_list, what, required);
}

bool oneOf(const std::string& s, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (s == n) return true;
  return false;
}

}  // namespace

void PreviewOptions::validate() const {
  requireField(position_m.allFinite(), "position_m", "must be finite");
  requireField(look_at_m.allFinite() && (look_at_m - position_m).norm() > 0.0, "look_at_m",
               "must be finite and differ from position_m");
  requireField(up.allFinite() && up.norm() > 0.0, "up", "must be a non-zero vector");
  requireField((look_at_m - position_m).normalized().cross(up.normalized()).norm() > 1e-6, "up",
               "must not be parallel to the viewing direction");
}

SceneDescription loadSceneDocument(const Document& doc, const std::string& base_dir) {
  const YAML::Node root = doc.root;
  const auto known_source = [](const std::string& t) {
    return oneOf(t, {"plane", "box", "terrain", "rocks", "heightmap", "mesh", "tube"});
  };
  const auto known_light = [](const std::string& t) { return oneOf(t, {"sun", "sky", "point", "spot"}); };
  const auto known_texture = [](const std::string& t) {
    return oneOf(t, {"constant", "noise", "image", "shapes", "collage", "checker"});
  };
  const auto known_model = [](const std::string& t) { return oneOf(t, {"lambertian", "oren_nayar"}); };
  checkTags(doc, root["sources"], "sources", "type", known_source, SourceOptions::knownTypes(),
           "source type", true);
  checkTags(doc, root["lights"], "lights", "type", known_light, LightOptions::knownTypes(),
           "light type", true);
  checkTags(doc, root["materials"], "materials", "model", known_model, "lambertian, oren_nayar",
           "reflectance model", false);
  if (root["materials"].IsSequence())
    for (std::size_t i = 0; i < root["materials"].size(); ++i)
      if (root["materials"][i].IsMap())
        checkTag(doc, root["materials"][i]["albedo"], "materials[" + std::to_string(i) + "].albedo", "type",
                 known_texture, TextureOptions::knownTypes(), "texture type", false);

  SceneDescription d;
  d.file = doc.file;
  d.base_dir = base_dir;
  config::readValue(doc, root, "", d.options);
  SceneOptions& o = d.options;

  const auto element = [&](const char* list, std::size_t i) { return root[list][i]; };
  const auto path = [](const char* list, std::size_t i) {
    return std::string(list) + "[" + std::to_string(i) + "]";
  };
  const auto guarded = [&](const YAML::Node& node, const std::string& p, const std::function<void()>& f) {
    try {
      f();
    } catch (const Error& e) {
      rethrowAt(doc, node, p, e);
    }
  };
  guarded(root["indirect"], "indirect", [&] { o.indirect.validate(); });
  guarded(root["preview"], "preview", [&] { o.preview.validate(); });

  if (o.materials.empty())
    throw Error(config::where(doc, root, "materials") + ": materials: at least one material is required");
  if (o.lights.empty())
    throw Error(config::where(doc, root, "lights") + ": lights: at least one light is required");
  if (o.sources.empty())
    throw Error(config::where(doc, root, "sources") + ": sources: at least one source is required");

  std::set<std::string> material_names;
  for (std::size_t i = 0; i < o.materials.size(); ++i) {
    const auto node = element("materials", i);
    const auto p = path("materials", i);
    d.material_where.push_back(config::where(doc, node, p) + ": " + p);
    guarded(node, p, [&] { o.materials[i].validate(); });
    if (!material_names.insert(o.materials[i].name).second)
      guarded(node, p, [&] { requireField(false, "name", "duplicate material '" + o.materials[i].name + "'"); });
  }
  int skies = 0;
  for (std::size_t i = 0; i < o.lights.size(); ++i) {
    const auto node = element("lights", i);
    const auto p = path("lights", i);
    d.light_where.push_back(config::where(doc, node, p) + ": " + p);
    guarded(node, p, [&] { o.lights[i].validate(); });
    if (o.lights[i].type == "sky" && ++skies > 1)
      guarded(node, p, [&] { requireField(false, "type", "at most one sky light"); });
  }
  std::set<std::string> source_names;
  std::vector<std::string> ground_types;
  for (std::size_t i = 0; i < o.sources.size(); ++i) {
    auto& s = o.sources[i];
    const auto node = element("sources", i);
    const auto p = path("sources", i);
    d.source_where.push_back(config::where(doc, node, p) + ": " + p);
    if (s.name.empty()) s.name = s.type + std::to_string(i);
    guarded(node, p, [&] {
      s.validate();
      requireField(material_names.count(s.material) > 0, "material",
                   "no material named '" + s.material + "'");
      requireField(source_names.insert(s.name).second, "name", "duplicate source name '" + s.name + "'");
      if (s.type == "rocks" && !s.rocks.ground.empty()) {
        bool found = false;
        for (std::size_t j = 0; j < i; ++j)
          if (o.sources[j].name == s.rocks.ground) {
            found = true;
            requireField(oneOf(o.sources[j].type, {"terrain", "heightmap", "tube"}), "ground",
                         "'" + s.rocks.ground + "' is a " + o.sources[j].type +
                             "; rocks rest on a terrain, heightmap or tube");
          }
        requireField(found, "ground", "no earlier source named '" + s.rocks.ground + "'");
      }
    });
  }
  return d;
}

SceneDescription loadSceneFile(const std::string& path, const std::vector<std::string>& overrides) {
  Document doc = config::loadFile(path);
  for (const auto& o : overrides) config::applyOverride(doc, o);
  return loadSceneDocument(doc, std::filesystem::path(path).parent_path().string());
}

SceneDescription loadSceneString(const std::string& text, const std::string& name,
                                 const std::string& base_dir) {
  return loadSceneDocument(config::loadString(text, name), base_dir);
}

Mat3 lookAtRotation(const Vec3& position, const Vec3& target, const Vec3& up) {
  const Vec3 d = target - position;
  require(d.allFinite() && d.norm() > 0.0, "lookAtRotation: target must differ from position");
  const Vec3 z = d.normalized();
  const Vec3 x_raw = z.cross(up);
  require(x_raw.norm() > 1e-9 * up.norm(), "lookAtRotation: up is parallel to the viewing direction");
  const Vec3 x = x_raw.normalized();
  const Vec3 y = z.cross(x);
  Mat3 R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = z;
  return R;
}

}  // namespace evio::scenes
