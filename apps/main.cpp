// pwl: the command-line program. Subcommands are added as the toolkit grows.
#include <cstdio>
int main() { std::puts("pwl"); return 0; }
