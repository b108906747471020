// libvolscissors: the GUI-free, ITK-free core (every module of src/ but io) as one shared library
// for other people's code (find_package(volscissors) -> volscissors::core, or pkg-config
// volscissors). The modules' objects are linked in whole; this file only names the version.
extern "C" const char* volscissors_version() { return VS_VERSION; }
