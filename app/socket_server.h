#pragma once

// The server of `ecvpose serve`: requests, one JSON line each, answered by a RecognitionService on standard input or on
// a Unix socket, until the input ends or SIGTERM / SIGINT ask it to stop.

#include <sys/types.h>

#include <functional>
#include <mutex>
#include <string>

#include "recognize/recognition_service.h"

namespace ecv::app {

/// Where and how a Unix socket is served.
struct SocketOptions {
  std::string path;
  mode_t mode = 0600;          // permissions of the socket file, whatever the umask
  int max_clients = 16;        // clients served at once; one more gets an error line and is closed
  double idle_timeout_s = 60;  // a client that sends nothing for this long is closed; 0: never
};

/// SIGTERM and SIGINT end the service after the request in hand (a blocking read or accept returns at once); SIGPIPE
/// is ignored, so that a client gone makes its write fail instead of ending the service.
void InstallStopHandlers();

/// Whether SIGTERM or SIGINT came since InstallStopHandlers.
bool StopRequested();

/// The permission bits an octal text such as "0660" spells; InputError unless it is 1 to 4 octal digits up to 0777.
mode_t ParseSocketMode(const std::string& text);

/// Answers the requests of one client, a line each, until its input ends, it goes, it sends nothing for longer than
/// the socket's receive timeout (said in an error line) or a stop is requested. `queue`, when given, is held for each
/// answer: one recognition at a time, as recognition uses every core.
void ServeClient(int in, int out, RecognitionService& service, std::mutex* queue = nullptr);

/// Clients of a socket at `socket.path` on threads of their own, each with tracks of its own (`make_service`), one
/// recognition at a time, until a stop is requested; the socket file is removed at the end.
void ServeSocket(const SocketOptions& socket, const std::function<RecognitionService()>& make_service);

}  // namespace ecv::app
