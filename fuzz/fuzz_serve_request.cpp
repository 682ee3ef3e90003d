// One request line of `ecvpose serve`, as a client sends it: parsed as the service parses it (ParseRequest), a frame
// in memory decoded (DecodeFrameBytes), and the answer written as the service writes it, which must read back as
// JSON whatever the line held (invalid UTF-8 in a line once ended the service). Reads no file. Also run over
// fuzz/corpus/serve_request by tests/recognize/serve_request_test.cpp.

#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "recognize/serve_request.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string line(reinterpret_cast<const char*>(data), size);
  ecv::ServeRequest request;
  std::string error;
  try {
    ecv::ParseRequest(line, ecv::RequestLimits(), &request);
    if (request.in_memory) ecv::DecodeFrameBytes(*request.in_memory);
  } catch (const ecv::InputError& refused) {  // the one expected answer to a bad line; others escape as findings
    error = refused.what();
  }
  const std::string answer = ecv::ResponseLine(ecv::ErrorResponse(request.id, error));
  const nlohmann::json read_back = nlohmann::json::parse(answer);  // throws (a finding) unless valid JSON
  if (!read_back.is_object() || read_back.size() != 2) __builtin_trap();
  return 0;
}
