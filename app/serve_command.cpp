// `ecvpose serve --db lib.sqlite`: one process that loads the library and the meshes once and answers recognition
// requests, JSON lines on standard input or on a Unix socket (RecognitionService holds the protocol, socket_server the
// server).

#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/frame_args.h"
#include "app/recognize_flags.h"
#include "app/socket_server.h"
#include "core/error.h"
#include "io/files.h"
#include "recognize/recognition_service.h"

namespace ecv::app {
namespace {

struct ServeArgs {
  RecognizerArgs recognizer;
  std::string socket;
  std::string socket_mode = "0600";  // octal permissions of the socket file
  std::vector<std::string> roots;    // folders frames are read below; none: the socket's default
  int max_clients = 16;              // socket clients served at once
  double idle_timeout_s = 60.0;      // a socket client that sends nothing for this long is closed; 0: never
  RequestLimits limits;
};

// The folders of --root; without one, the working directory for a socket and anywhere for standard input. Said on
// standard error.
ReadRoots ServeRoots(const ServeArgs& args) {
  std::vector<std::string> folders = args.roots;
  if (folders.empty() && !args.socket.empty()) folders.push_back(".");
  ReadRoots roots(folders);
  std::cerr << "serve: frames read " << (folders.empty() ? "anywhere (no --root)" : "below");
  for (const std::filesystem::path& folder : roots.folders()) std::cerr << ' ' << folder.string();
  std::cerr << '\n';
  return roots;
}

int RunServe(const ServeArgs& args) {
  const SocketOptions socket{args.socket, ParseSocketMode(args.socket_mode), args.max_clients, args.idle_timeout_s};
  const ReadRoots roots = ServeRoots(args);
  const StreamRecognizerOptions options =
      ShareThreads(RecognizerOptionsFromArgs(args.recognizer), args.recognizer.stream);
  const LoadedRecognizer loaded = LoadRecognizer(args.recognizer, options.track, "serve");
  const auto make_service = [&] {
    return RecognitionService(*loaded.recognizer, args.recognizer.stream, args.limits, roots,
                              MakeRecognizerFactory(*loaded.library, options.search));
  };
  InstallStopHandlers();
  if (!args.socket.empty()) {
    ServeSocket(socket, make_service);
  } else {
    RecognitionService service = make_service();
    std::cerr << "serve: ready, reading requests on standard input\n";
    ServeClient(STDIN_FILENO, STDOUT_FILENO, service);
  }
  std::cerr << "serve: " << (StopRequested() ? "stopped" : "input ended") << '\n';
  return kExitOk;
}

}  // namespace

CommandAction SetupServeCommand(CLI::App& command) {
  auto args = std::make_shared<ServeArgs>();
  AddRecognizerFlags(command, &args->recognizer);
  command.add_option("--socket", args->socket,
                     "Serve a Unix socket at this path, each client on a thread and with tracks of its own, one "
                     "recognition at a time (default: standard input and output)");
  command.add_option("--max-clients", args->max_clients, "Socket clients served at once: one more gets an error line")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  command
      .add_option("--idle-timeout", args->idle_timeout_s,
                  "Seconds a socket client may send nothing before it is closed (0: never)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  command.add_option("--root", args->roots,
                     "Read frames only below this folder (repeatable): regular files whose path, links followed, "
                     "lies below a --root (default: the working directory with --socket; anywhere on standard input)");
  command
      .add_option("--socket-mode", args->socket_mode,
                  "Permissions of the socket file, octal, whatever the umask: 0600 lets only this user connect, 0660 "
                  "also the group")
      ->capture_default_str();
  command
      .add_option("--max-request-bytes", args->limits.max_bytes,
                  "Longest request line, bytes: a longer one gets an error answer and is skipped, not kept")
      ->capture_default_str()
      ->check(AtLeastOne());
  command.footer(
      "Requests, one JSON object per line: {\"frame\": FRAME}, {\"color\": PATH, \"depth\": PATH, \"depth_scale\": "
      "S,\n\"camera\": [fx, fy, cx, cy]} or the images themselves, {\"color_png\": BASE64, \"depth_png\": BASE64, "
      "\"depth_scale\": S,\n\"camera\": [...]}, with optional \"id\" (echoed), \"track\": true|false (default: "
      "--track) and \"reset\": true.\nEach gets one line: the detections as `recognize --out-json` writes them, or "
      "{\"id\": ..., \"error\": ...}\n(also for a line past --max-request-bytes, nested deeper than 64 or not UTF-8, "
      "and for a file outside --root); the service goes on.\nSIGTERM ends the service after the request in hand (exit "
      "0). Protocol and security: docs/serve.md.");
  return [args] { return RunServe(*args); };
}

}  // namespace ecv::app
