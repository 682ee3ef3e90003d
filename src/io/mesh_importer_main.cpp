// ecvpose-mesh-import PATH PARENT_PID: reads one mesh file with assimp for LoadMesh, which starts it, and writes the
// result to standard output. A file that crashes the importer or makes it loop ends only this process.

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <iostream>
#include <string>

#include "io/mesh_io.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: ecvpose-mesh-import MESH_FILE PARENT_PID (started by ecvpose, not meant to be run by hand)\n";
    return 2;
  }
  prctl(PR_SET_PDEATHSIG, SIGKILL);                    // ends with the process that waits for it
  if (std::to_string(getppid()) != argv[2]) return 4;  // that process has gone already
  return ecv::RunMeshImporter(argv[1], STDOUT_FILENO);
}
