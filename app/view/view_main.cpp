// `ecvpose-view --db LIB --sequence SOURCE`: a window on the recognizer. It runs `ecvpose recognize --sequence SOURCE
// --out-json - --overlay DIR` in a child process (OSMesa there, Qt and libGL here) and shows each frame's detection
// drawing with the detections' names, scores and track states and the frames per second. Only this file turns
// exceptions into exit codes: 1 bad input (or the recognizer's code), 2 bad usage.

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/view/recognizer_child.h"
#include "app/view/viewer.h"

namespace {

constexpr int kExitOk = 0, kExitBadInput = 1, kExitBadUsage = 2;

volatile std::sig_atomic_t stop_requested = 0;
extern "C" void RequestStop(int /*signal*/) {
  stop_requested = 1;
}

struct ViewArgs {
  std::string library, sequence;
  std::string ecvpose;  ///< the ecvpose program; default: the one beside ecvpose-view
  ecv::view::ViewerOptions viewer;
};

// Why no window can be opened, or "" when an X display seems to be there. A local display (":N") is tried by
// connecting to its socket, so that a stale DISPLAY is an error here rather than an abort inside Qt.
std::string DisplayProblem() {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if (wayland != nullptr && *wayland != '\0') return "";
    return "no display: DISPLAY is not set (the viewer needs an X display; without one use `ecvpose recognize "
           "--sequence ... --overlay DIR`)";
  }
  const std::string name = display;
  if (name[0] != ':' && name.rfind("unix:", 0) != 0) return "";  // host:N (e.g. ssh -X): left to Qt
  const std::string number = name.substr(name.find(':') + 1, name.find('.') - name.find(':') - 1);
  const std::string socket_path = "/tmp/.X11-unix/X" + number;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  socket_path.copy(address.sun_path, sizeof(address.sun_path) - 1);
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const bool connected =
      fd >= 0 && connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;  // NOLINT
  if (fd >= 0) close(fd);
  if (connected) return "";
  return "no display: DISPLAY=" + name + " but no X server listens on " + socket_path;
}

// The ecvpose program beside this one (build tree and install alike).
std::string EcvposeBesideUs() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string("ecvpose") : (self.parent_path() / "ecvpose").string();
}

// The recognizer's arguments: the sequence, its detections on standard output and each frame's picture in `pictures`,
// then the flags ecvpose-view does not know, passed on as given.
std::vector<std::string> ChildArguments(const ViewArgs& args, const std::string& pictures,
                                        const std::vector<std::string>& extra) {
  std::vector<std::string> arguments = {"recognize",  "--db", args.library, "--sequence", args.sequence,
                                        "--out-json", "-",    "--overlay",  pictures};
  arguments.insert(arguments.end(), extra.begin(), extra.end());
  return arguments;
}

// A fresh directory for the recognizer's pictures, removed with everything in it when this goes out of scope.
class PictureDirectory {
 public:
  PictureDirectory() {
    std::string pattern = (std::filesystem::temp_directory_path() / "ecvpose-view-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error(pattern + ": cannot make a temporary directory");
    path_ = pattern;
  }
  ~PictureDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  PictureDirectory(const PictureDirectory&) = delete;
  PictureDirectory& operator=(const PictureDirectory&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

void SetUpFlags(CLI::App& app, ViewArgs* args) {
  app.add_option("--db", args->library, "Model library (SQLite), as for ecvpose recognize")->required();
  app.add_option("--sequence", args->sequence,
                 "Frames to show: an OpenNI2 camera (openni2://, openni2://URI), a FILE.oni recording or any\n"
                 "sequence ecvpose recognize reads (a folder of frame JSONs, a YCB-Video video, a BOP scene, a list)")
      ->required();
  app.add_option("--save-dir", args->viewer.save_dir, "Where s saves the shown picture (ecvpose-view-NNNN.png)")
      ->capture_default_str();
  app.add_flag("--exit-at-end", args->viewer.exit_at_end,
               "Close when the sequence ends (default: keep its last frame shown until q)");
  app.add_option("--ecvpose", args->ecvpose, "The ecvpose program to run (default: the one beside ecvpose-view)");
  app.allow_extras();
  app.footer(
      "Any other flag goes to `ecvpose recognize` as given (--track, --camera, --min-score, ...; see\n"
      "`ecvpose recognize --help`), except --out-json and --overlay, which the viewer uses itself.\n"
      "Keys: space pause/resume, n or right arrow one frame while paused, s save the picture, q or Esc quit.\n"
      "Example:\n  ecvpose-view --db lib.sqlite --sequence recording.oni --track");
}

int Run(const ViewArgs& args, const std::vector<std::string>& extra) {
  for (const char* flag : {"--out-json", "--overlay"}) {
    if (std::find(extra.begin(), extra.end(), flag) != extra.end()) {
      std::cerr << "ecvpose-view: " << flag << " is the viewer's own channel to the recognizer; record with "
                << "`ecvpose recognize` instead\n";
      return kExitBadUsage;
    }
  }
  if (const std::string problem = DisplayProblem(); !problem.empty()) {
    std::cerr << "ecvpose-view: " << problem << '\n';
    return kExitBadInput;
  }
  const std::string program = args.ecvpose.empty() ? EcvposeBesideUs() : args.ecvpose;
  if (access(program.c_str(), X_OK) != 0) {
    std::cerr << "ecvpose-view: " << program << ": expected the ecvpose program (beside ecvpose-view, or --ecvpose)\n";
    return kExitBadInput;
  }
  const PictureDirectory pictures;
  ecv::view::RecognizerChild child(program, ChildArguments(args, pictures.path(), extra));
  return ecv::view::RunViewer(child, args.viewer, stop_requested);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ecvpose-view: a window on `ecvpose recognize`: each frame with its detections as they come"};
  ViewArgs args;
  SetUpFlags(app, &args);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? kExitOk : kExitBadUsage;
  }
  struct sigaction action {};
  action.sa_handler = RequestStop;  // no SA_RESTART: a wait returns, and the window loop sees the request
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  try {
    return Run(args, app.remaining());
  } catch (const std::exception& error) {
    std::cerr << "ecvpose-view: error: " << error.what() << '\n';
    return kExitBadInput;
  }
}
