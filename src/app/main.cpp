#include "app/cli.hpp"

int main(int argc, char** argv) { return pathlab::run_cli(argc, argv); }
