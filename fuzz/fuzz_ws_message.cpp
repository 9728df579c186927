// libFuzzer harness: one WebSocket text frame through the path the daemon gives it — bounded
// parse, ws-client schema, then the session: an editing session of a strip preset receives the
// frame as a participant's message and runs it to completion. Errors are answers; crashes,
// sanitizer reports and non-finite state abort.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/Session.h"
#include "devsurf/server/Tokens.h"
#include "server/SessionTesting.h"

namespace {

using nlohmann::json;
using namespace devsurf;

const proto::Scene& presetScene() {
  static const proto::Scene scene = [] {
    std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/strip-lifted-corner.json");
    return proto::sceneFromJson(json::parse(file));
  }();
  return scene;
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
  server::testing::ManualExecutor ex;
  server::testing::Inbox inbox;
  auto session = std::make_shared<server::Session>("fuzz", presetScene(),
                                                   server::Session::Tokens{server::tokenHash("e"), server::tokenHash("v")},
                                                   server::SessionSettings{}, ex.scheduler(), nullptr, nullptr, false);
  const int pid = session->join(server::Role::Edit, "fuzz", inbox.sink());
  ex.runAll();
  session->post(pid, message);
  ex.runAll();
  const json scene = session->sceneJson();
  if (scene.dump().find("null") != std::string::npos) std::abort();  // a NaN reached the scene
  return 0;
}
