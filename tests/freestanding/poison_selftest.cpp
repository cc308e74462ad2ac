// Must NOT link when the heap is poisoned: proves the poison catches `new`.
// The pointer escapes through a volatile so the allocation cannot be elided.
int* volatile g_escape = nullptr;

int main() {
  g_escape = new int(42);
  return *g_escape == 42 ? 0 : 1;
}
