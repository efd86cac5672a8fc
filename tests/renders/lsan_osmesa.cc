// LeakSanitizer (the AIRTWIN_SANITIZE build): Mesa's OSMesa keeps a small framebuffer record
// (~850 bytes) for every client buffer bound with OSMesaMakeCurrent and offers no call to free
// it; OSMesaDestroyContext leaves it behind. That is Mesa's, not ours: suppress leaks whose stack
// is inside libOSMesa, and nothing else. LeakSanitizer looks this hook up in the executable.

extern "C" const char* __lsan_default_suppressions();
extern "C" const char* __lsan_default_suppressions() { return "leak:libOSMesa.so\n"; }
