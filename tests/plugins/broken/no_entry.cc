// A shared library that is not a bimart plug-in.
extern "C" int not_a_plugin() { return 42; }
