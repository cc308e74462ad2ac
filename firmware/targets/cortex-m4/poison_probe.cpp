// Must NOT link: allocates with operator new under the heap poison, so the
// build checks that the poison names the Cortex-M4's own `new` (_Znwj).
int* volatile g_escape = nullptr;

extern "C" void firmware_main() {
  g_escape = new int(42);
  for (;;) {
  }
}
