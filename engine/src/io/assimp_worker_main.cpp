#include "io/assimp_worker.h"

int main(int argc, char** argv) { return retile::assimpWorkerMain(argc, argv); }
