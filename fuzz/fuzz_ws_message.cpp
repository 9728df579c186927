// libFuzzer harness: one WebSocket text frame through the path the daemon gives it — bounded
// parse, ws-client schema, then the session: an editing session receives the frame as a
// participant's message and runs it to completion. The session is of the kind the message
// addresses (a composite for {vertex}/{edge} targets and set_crease, a quasi_strip for curves
// c1/c2 and its set_params fields, a conical_strip for p/q and its fields, else a strip), so
// every kind's dispatch is reached. Errors are answers; crashes, sanitizer reports, an `internal`
// error, a `null` or a non-finite float32 in any message the session sends, and NaN in its scene
// abort.
//
// Bounded for speed (not for safety: the daemon's own limits are tested elsewhere): a few
// iterations per drag and release, small quasi/conical sampling; set_params sizes are clamped.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Geometry.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/Session.h"
#include "devsurf/server/Tokens.h"
#include "server/SessionTesting.h"

namespace {

using nlohmann::json;
using namespace devsurf;

enum Kind { kStrip, kComposite, kQuasi, kConical, kKinds };

json readExample(const char* name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  return json::parse(file);
}

const proto::Scene& presetScene(Kind kind) {
  static const proto::Scene scenes[kKinds] = {
      proto::sceneFromJson(readExample("strip-lifted-corner.json")),
      proto::sceneFromJson(readExample("composite-curved-fold.json")),
      [] {
        json scene = readExample("quasi-strip-twisted.json");
        scene["model"]["samples"] = 30;
        scene["model"]["mapping"]["coefficients"] = 12;
        scene["model"]["max_iterations"] = 10;
        return proto::sceneFromJson(scene);
      }(),
      [] {
        json scene = readExample("conical-strip-hull.json");
        scene["model"]["np"] = 16;
        scene["model"]["nq"] = 18;
        return proto::sceneFromJson(scene);
      }()};
  return scenes[kind];
}

/// The session kind a message addresses.
Kind kindOf(const json& m) {
  const std::string type = m["type"];
  if (type == "set_crease") return kComposite;
  if (type == "set_params") {
    for (const char* k : {"np", "nq", "h3", "h4", "ra", "objective", "g1"})
      if (m["params"].contains(k)) return kConical;
    return kQuasi;
  }
  const json* target = m.contains("target") ? &m["target"] : m.contains("selection") ? &m["selection"] : nullptr;
  if (!target || !target->is_object()) return kStrip;
  if (target->contains("vertex") || target->contains("edge")) return kComposite;
  const std::string curve = target->value("curve", "a");
  if (curve == "c1" || curve == "c2") return kQuasi;
  if (curve == "p" || curve == "q") return kConical;
  return kStrip;
}

/// Clamps what scales a quasi/conical rebuild (the sizes the daemon's limits are about).
void boundParams(json& m) {
  if (m["type"] != "set_params") return;
  json& p = m["params"];
  auto clamp = [](json& parent, const char* key, int most) {
    if (parent.contains(key) && parent[key].is_number_integer() && parent[key].get<double>() > most) parent[key] = most;
  };
  clamp(p, "samples", 40);
  clamp(p, "max_iterations", 10);
  clamp(p, "np", 24);
  clamp(p, "nq", 24);
  if (p.contains("mapping")) clamp(p["mapping"], "coefficients", 16);
}

/// Aborts on a `null` outside the keys that may be null, or a non-finite float32 array element.
void checkOutgoing(const json& v, const char* key) {
  if (v.is_null()) {
    if (std::strcmp(key, "selection") && std::strcmp(key, "dragging") && std::strcmp(key, "projection_point"))
      std::abort();  // a NaN serialized as null, or a missing value
  } else if (v.is_number_float()) {
    if (!std::isfinite(v.get<double>())) std::abort();
  } else if (v.is_array()) {
    for (const json& e : v) checkOutgoing(e, key);
  } else if (v.is_object()) {
    if (v.value("dtype", "") == "float32" && v.contains("data") && v["data"].is_string()) {
      const std::string bytes = proto::base64Decode(v["data"]);
      for (std::size_t i = 0; i + 4 <= bytes.size(); i += 4) {
        float f;
        std::memcpy(&f, bytes.data() + i, 4);
        if (!std::isfinite(f)) std::abort();  // a non-finite coordinate or metric streamed
      }
    }
    for (const auto& [k, e] : v.items()) checkOutgoing(e, k.c_str());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > (1u << 16)) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  json message;
  try {
    message = proto::parseBoundedJson(text);
  } catch (const std::exception&) {
    return 0;  // too_deep / invalid_json
  }
  (void)proto::echoableId(message.is_object() && message.contains("op") ? message["op"] : json());
  if (!proto::schemaRegistry().validate(message, "ws-client.schema.json", 1).empty()) return 0;
  if (message["type"] == "join") return 0;
  boundParams(message);
  server::SessionSettings settings;
  settings.dragIterations = 2;
  settings.dragTimeBudgetMs = 5.0;
  settings.releaseIterations = 3;
  settings.releaseTimeBudgetMs = 100.0;
  settings.maxIterationsPerRequest = 5;
  settings.surfaceSamples = 16;
  settings.compositeSamplesPerSpan = 3;
  // The preset is built without a time budget (an instrumented build beside the ASan hostile
  // client once took longer than 5 s to build and solve the conical strip, and the constructor's
  // time_budget error is not what this harness looks for); the messages then have one.
  settings.rebuildTimeBudgetMs = 0.0;
  server::testing::ManualExecutor ex;
  auto session = std::make_shared<server::Session>("fuzz", presetScene(kindOf(message)),
                                                   server::Session::Tokens{server::tokenHash("e"), server::tokenHash("v")},
                                                   settings, ex.scheduler(), nullptr, nullptr, false);
  session->setRebuildTimeBudget(5000.0);
  const int pid = session->join(server::Role::Edit, "fuzz", [](std::string out, server::Delivery, const std::string&) {
    const json m = json::parse(out);
    if (m.value("code", "") == "internal") std::abort();  // an exception escaped into an `internal` error
    checkOutgoing(m, "");
  });
  ex.runAll();
  session->post(pid, message);
  ex.runAll();
  checkOutgoing(session->sceneJson(), "");
  return 0;
}
