/*
 * frusta view: the scene in an SDL2 window. Input and display run on the
 * main thread and rendering on a worker (whose passes use every thread);
 * any change of camera or mode abandons the pass under way (render/frame.c
 * skips its remaining tiles) and starts afresh, so input is acted on
 * within a tile's time. With --frames the window renders a fixed number of
 * frames in lockstep, one pass each, along a camera path or a turntable,
 * and exits: the same pictures every run, for scripts and tests. There too
 * the worker renders the next frame while the main thread shows the last.
 */
#include <SDL2/SDL.h>
#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "base/timer.h"
#include "cli.h"
#include "cli_path.h"
#include "cli_scene_file.h"
#include "commands.h"
#include "io/image_write.h"
#include "view_camera.h"
#include "view_renderer.h"

static const char *const keys_help =
    "keys: drag to orbit (left), pan (right or middle); wheel zooms; W A S D Q E fly (shift: faster);\n"
    "1-7 eyelight normals shadows softshadow whitted ao path; M trace mode; N denoiser; T temporal blending;\n"
    "P prints the camera; K screenshot (frusta-NNNN.png); H this help; Esc quits\n";

typedef struct view_shared {
  pthread_mutex_t lock;
  pthread_cond_t wake;  /* for the worker: want changed, a screenshot, quit */
  pthread_cond_t ready; /* for the main thread: a frame (lockstep), or the worker stopped */
  view_settings want;
  unsigned gen;         /* bumped on every change of want */
  int quit, error;
  /* scripted frames: one pass for each gen, even where want stays the
   * same, and each frame published; step_shot names its screenshot */
  int lockstep;
  char step_shot[4096];
  float reused;
  int cancel;           /* set (atomically) to abandon the pass under way */
  uint8_t *frame;       /* the newest frame, BGRA */
  int fw, fh, spp;
  unsigned frame_id;
  double seconds, denoise_seconds;
  uint64_t rays;
  int shot;             /* a screenshot is asked for (interactive) */
  char shot_name[64];
  /* how soon a change is answered: from the first change the worker has
   * not picked up (0: none) to the start of the new view's pass */
  double changed_at;
  float answer_ms[4096];
  int answers;
} view_shared;

typedef struct view_app {
  view_renderer r;
  view_shared sh;
  SDL_Window *win;
  SDL_Renderer *ren;
  SDL_Texture *tex;
  int tw, th;
  const char *scene_name;
  FILE *record;
} view_app;

/* Abandons the pass under way (on: 1) or lets passes run (0): the flag the
 * worker reads and the renderer's own. */
static void set_cancel(view_app *app, int on) {
  __atomic_store_n(&app->sh.cancel, on, __ATOMIC_RELAXED);
  view_renderer_cancel(&app->r, on);
}

static void *worker(void *arg) {
  view_app *app = arg;
  view_shared *sh = &app->sh;
  unsigned applied = 0;
  int have = 0;
  pthread_mutex_lock(&sh->lock);
  for (;;) {
    while (!sh->quit && have && applied == sh->gen && (sh->lockstep || view_renderer_done(&app->r)) && !sh->shot)
      pthread_cond_wait(&sh->wake, &sh->lock);
    if (sh->quit) break;
    if (sh->shot) { /* written here, where the image lives */
      sh->shot = 0;
      char name[64];
      memcpy(name, sh->shot_name, sizeof name);
      pthread_mutex_unlock(&app->sh.lock);
      if (!view_renderer_screenshot(&app->r, name)) printf("screenshot -> %s\n", name);
      pthread_mutex_lock(&sh->lock);
      continue;
    }
    const view_settings want = sh->want;
    const unsigned gen = sh->gen;
    char step_shot[sizeof sh->step_shot];
    memcpy(step_shot, sh->step_shot, sizeof step_shot);
    set_cancel(app, 0);
    pthread_mutex_unlock(&sh->lock);
    int rc = 0, fresh = 0;
    if (!have || applied != gen) {
      rc = view_renderer_apply(&app->r, &want);
      applied = gen, have = 1;
      pthread_mutex_lock(&sh->lock);
      if (sh->changed_at > 0.0 && sh->answers < (int)(sizeof sh->answer_ms / sizeof sh->answer_ms[0]))
        sh->answer_ms[sh->answers++] = (float)((fr_seconds() - sh->changed_at) * 1e3);
      sh->changed_at = 0.0;
      pthread_mutex_unlock(&sh->lock);
    }
    if (!rc && (fresh = view_renderer_pass(&app->r)) < 0) rc = 1;
    /* every step shows a frame, the last one again when nothing was left to
     * do; a step abandoned (the window closed) shows and writes nothing */
    if (!rc && sh->lockstep && !__atomic_load_n(&sh->cancel, __ATOMIC_RELAXED)) {
      fresh = 1;
      if (!app->r.bgra) rc = cli_error(1, "view: nothing rendered");
      else if (step_shot[0]) rc = view_renderer_screenshot(&app->r, step_shot);
    }
    pthread_mutex_lock(&sh->lock);
    if (rc) { sh->error = rc, sh->quit = 1; break; }
    if (fresh && (gen == sh->gen || sh->lockstep)) {
      const size_t bytes = (size_t)want.width * (size_t)want.height * 4;
      if (want.width != sh->fw || want.height != sh->fh) {
        uint8_t *f = realloc(sh->frame, bytes);
        if (!f) { sh->error = cli_error(1, "out of memory for a frame"), sh->quit = 1; break; }
        sh->frame = f, sh->fw = want.width, sh->fh = want.height;
      }
      memcpy(sh->frame, app->r.bgra, bytes);
      sh->frame_id++;
      sh->spp = view_renderer_spp(&app->r);
      sh->seconds = app->r.seconds, sh->denoise_seconds = app->r.denoise_seconds, sh->rays = app->r.rays;
      sh->reused = view_renderer_reused(&app->r);
      pthread_cond_signal(&sh->ready);
    }
  }
  pthread_cond_signal(&sh->ready);
  pthread_mutex_unlock(&sh->lock);
  SDL_Event ev = {.type = SDL_QUIT}; /* wake the main thread if it waits */
  SDL_PushEvent(&ev);
  return NULL;
}

static int show(view_app *app, const uint8_t *bgra, int w, int h) {
  if (!app->tex || app->tw != w || app->th != h) {
    if (app->tex) SDL_DestroyTexture(app->tex);
    app->tex = SDL_CreateTexture(app->ren, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_STREAMING, w, h);
    if (!app->tex) return cli_error(1, "view: cannot make a %dx%d texture: %s", w, h, SDL_GetError());
    app->tw = w, app->th = h;
  }
  SDL_UpdateTexture(app->tex, NULL, bgra, w * 4);
  SDL_RenderClear(app->ren);
  SDL_RenderCopy(app->ren, app->tex, NULL, NULL);
  SDL_RenderPresent(app->ren);
  return 0;
}

static void set_title(view_app *app, const view_settings *s, double fps, double mrays, int spp) {
  char t[256];
  snprintf(t, sizeof t, "frusta - %s - %s - %s - %.1f fps - %.1f Mrays/s - %d spp%s", app->scene_name,
           fr_shade_mode_name(s->mode), view_trace_names[s->trace], fps, mrays, spp,
           s->denoise && fr_shade_mode_progressive(s->mode) ? " - denoised" : "");
  SDL_SetWindowTitle(app->win, t);
}

static int cmp_float(const void *a, const void *b) {
  const float x = *(const float *)a, y = *(const float *)b;
  return x < y ? -1 : x > y;
}

/* Interactive: returns the exit code. */
static int run_interactive(view_app *app, view_settings init, float speed) {
  view_shared *sh = &app->sh;
  sh->want = init;
  sh->gen = 1;
  pthread_t th;
  if (pthread_create(&th, NULL, worker, app)) return cli_error(1, "view: cannot start the render thread");
  fputs(keys_help, stdout);
  fflush(stdout);
  unsigned shown = 0;
  int shots = 0, rc = 0;
  double last = fr_seconds(), fps_t0 = last;
  int fps_frames = 0;
  double fps = 0.0;
  for (int running = 1; running;) {
    SDL_Event ev;
    view_settings w;
    pthread_mutex_lock(&sh->lock);
    w = sh->want;
    const int stopped = sh->quit;
    pthread_mutex_unlock(&sh->lock);
    if (stopped) break;
    view_settings before = w;
    int got = SDL_WaitEventTimeout(&ev, 8);
    while (got) {
      switch (ev.type) {
      case SDL_QUIT: running = 0; break;
      case SDL_WINDOWEVENT:
        if (ev.window.event == SDL_WINDOWEVENT_SIZE_CHANGED && ev.window.data1 >= 16 && ev.window.data2 >= 16)
          w.width = ev.window.data1, w.height = ev.window.data2;
        break;
      case SDL_MOUSEMOTION:
        if (ev.motion.state & SDL_BUTTON_LMASK) view_camera_orbit(&w.cam, -0.005f * ev.motion.xrel, 0.005f * ev.motion.yrel);
        else if (ev.motion.state & (SDL_BUTTON_RMASK | SDL_BUTTON_MMASK)) {
          const float k = 2.0f * tanf(0.5f * w.cam.fov * 3.14159265f / 180.0f) / (float)w.height;
          view_camera_pan(&w.cam, -k * ev.motion.xrel, k * ev.motion.yrel);
        }
        break;
      case SDL_MOUSEWHEEL: view_camera_zoom(&w.cam, powf(0.9f, (float)ev.wheel.y)); break;
      case SDL_KEYDOWN: {
        const SDL_Keycode k = ev.key.keysym.sym;
        if (k == SDLK_ESCAPE) running = 0;
        else if (k >= SDLK_1 && k <= SDLK_7) w.mode = (fr_shade_mode)(k - SDLK_1);
        else if (k == SDLK_m) w.trace = (view_trace)((w.trace + 1) % VIEW_TRACE_COUNT);
        else if (k == SDLK_n) w.denoise = !w.denoise;
        else if (k == SDLK_t) w.temporal = !w.temporal;
        else if (k == SDLK_p) { view_camera_print(stdout, &w.cam); fflush(stdout); }
        else if (k == SDLK_h) { fputs(keys_help, stdout); fflush(stdout); }
        else if (k == SDLK_k) {
          pthread_mutex_lock(&sh->lock);
          snprintf(sh->shot_name, sizeof sh->shot_name, "frusta-%04d.png", shots++);
          sh->shot = 1;
          pthread_cond_signal(&sh->wake);
          pthread_mutex_unlock(&sh->lock);
        }
        break;
      }
      default: break;
      }
      got = SDL_PollEvent(&ev);
    }
    /* flying: held keys move the camera by the time since the last look */
    const double now = fr_seconds();
    const float dt = (float)fmin(now - last, 0.1);
    last = now;
    const Uint8 *ks = SDL_GetKeyboardState(NULL);
    const float v = speed * dt * (ks[SDL_SCANCODE_LSHIFT] || ks[SDL_SCANCODE_RSHIFT] ? 4.0f : 1.0f);
    const float fwd = (float)(ks[SDL_SCANCODE_W] - ks[SDL_SCANCODE_S]), side = (float)(ks[SDL_SCANCODE_D] - ks[SDL_SCANCODE_A]);
    const float rise = (float)(ks[SDL_SCANCODE_E] - ks[SDL_SCANCODE_Q]);
    if (fwd || side || rise) view_camera_fly(&w.cam, fwd * v, side * v, rise * v);
    if (memcmp(&w, &before, sizeof w)) {
      pthread_mutex_lock(&sh->lock);
      sh->want = w;
      sh->gen++;
      if (sh->changed_at == 0.0) sh->changed_at = fr_seconds();
      set_cancel(app, 1);
      pthread_cond_signal(&sh->wake);
      pthread_mutex_unlock(&sh->lock);
      if (app->record) view_camera_path_write(app->record, &w.cam);
    }
    pthread_mutex_lock(&sh->lock);
    if (sh->frame_id != shown) {
      shown = sh->frame_id;
      rc = show(app, sh->frame, sh->fw, sh->fh);
      fps_frames++;
      if (now - fps_t0 > 0.5) fps = fps_frames / (now - fps_t0), fps_frames = 0, fps_t0 = now;
      set_title(app, &sh->want, fps, sh->rays / fmax(sh->seconds, 1e-9) * 1e-6, sh->spp);
    }
    pthread_mutex_unlock(&sh->lock);
    if (rc) break;
  }
  pthread_mutex_lock(&sh->lock);
  sh->quit = 1;
  set_cancel(app, 1);
  pthread_cond_signal(&sh->wake);
  pthread_mutex_unlock(&sh->lock);
  pthread_join(th, NULL);
  if (sh->answers) { /* how responsive it was */
    qsort(sh->answer_ms, (size_t)sh->answers, sizeof sh->answer_ms[0], cmp_float);
    printf("view: %d changes answered in %.1f ms median, %.1f ms at most (the pass under way abandoned, the new "
           "view begun)\n", sh->answers, (double)sh->answer_ms[sh->answers / 2], (double)sh->answer_ms[sh->answers - 1]);
  }
  return rc ? rc : sh->error;
}

/* A screenshot name for frame i: '#' in name becomes the frame number. */
static void frame_name(const char *name, int i, char *out, size_t n) {
  const char *hash = strchr(name, '#');
  if (!hash) snprintf(out, n, "%s", name);
  else snprintf(out, n, "%.*s%04d%s", (int)(hash - name), name, i, hash + 1);
}

/* The settings of scripted frame i: along the camera path, or turned
 * from the last frame's by the turntable's angle. */
static void frame_settings(view_settings *s, int i, const view_camera *path, size_t npath, float turntable) {
  if (npath) s->cam = path[(size_t)i < npath ? (size_t)i : npath - 1];
  else if (i > 0 && turntable != 0.0f) view_camera_orbit(&s->cam, turntable * 3.14159265f / 180.0f, 0.0f);
}

/* Hands frame i's settings (and screenshot, if any) to the worker; under
 * the lock. */
static void frame_ask(view_app *app, const view_settings *s, int i, int frames, const char *screenshot) {
  view_shared *sh = &app->sh;
  if (app->record) view_camera_path_write(app->record, &s->cam);
  sh->want = *s;
  sh->gen++;
  sh->step_shot[0] = 0;
  if (screenshot && (strchr(screenshot, '#') || i == frames - 1))
    frame_name(screenshot, i, sh->step_shot, sizeof sh->step_shot);
  pthread_cond_signal(&sh->wake);
}

/* Scripted: frames in lockstep, one pass each, the worker rendering frame
 * i + 1 while this thread shows frame i; a frame's time is from the last
 * one shown to its own. Returns the exit code. */
static int run_frames(view_app *app, view_settings s, int frames, const view_camera *path, size_t npath, float turntable,
                      const char *screenshot) {
  view_shared *sh = &app->sh;
  const size_t bytes = (size_t)s.width * (size_t)s.height * 4;
  uint8_t *shown = malloc(bytes);
  if (!shown) return cli_error(1, "out of memory for a frame");
  sh->lockstep = 1;
  frame_settings(&s, 0, path, npath, turntable);
  frame_ask(app, &s, 0, frames, screenshot);
  pthread_t th;
  if (pthread_create(&th, NULL, worker, app)) {
    free(shown);
    return cli_error(1, "view: cannot start the render thread");
  }
  double total = 0.0, last = fr_seconds();
  int rc = 0, done = 0;
  for (int i = 0; i < frames && !rc; i++) {
    pthread_mutex_lock(&sh->lock);
    while (sh->frame_id == (unsigned)i && !sh->quit) pthread_cond_wait(&sh->ready, &sh->lock);
    if (sh->frame_id == (unsigned)i) { /* the worker stopped (its error is in sh->error) */
      pthread_mutex_unlock(&sh->lock);
      break;
    }
    memcpy(shown, sh->frame, bytes);
    const double seconds = sh->seconds, denoise = sh->denoise_seconds, reused = sh->reused;
    const uint64_t rays = sh->rays;
    const int spp = sh->spp;
    if (i + 1 < frames) {
      frame_settings(&s, i + 1, path, npath, turntable);
      frame_ask(app, &s, i + 1, frames, screenshot);
    }
    pthread_mutex_unlock(&sh->lock);
    rc = show(app, shown, s.width, s.height);
    const double now = fr_seconds(), dt = now - last;
    last = now;
    total += dt;
    printf("frame %d: %.2f ms render %.2f ms denoise %.2f ms spp=%d mrays=%.2f reused=%.0f%%\n", i, dt * 1e3,
           seconds * 1e3, denoise * 1e3, spp, rays / fmax(seconds, 1e-9) * 1e-6, 100.0 * reused);
    set_title(app, &s, 1.0 / dt, rays / fmax(seconds, 1e-9) * 1e-6, spp);
    done = i + 1;
    SDL_Event ev;
    while (SDL_PollEvent(&ev))
      if (ev.type == SDL_QUIT) frames = done; /* closed: stop after this frame */
  }
  pthread_mutex_lock(&sh->lock);
  sh->quit = 1;
  set_cancel(app, 1); /* a frame asked for and no longer wanted */
  pthread_cond_signal(&sh->wake);
  pthread_mutex_unlock(&sh->lock);
  pthread_join(th, NULL);
  free(shown);
  if (rc || sh->error) return rc ? rc : sh->error;
  printf("view scene=%s shade=%s trace=%s size=%dx%d frames=%d seconds=%.3f fps=%.2f%s%s\n", app->scene_name,
         fr_shade_mode_name(s.mode), view_trace_names[s.trace], s.width, s.height, done, total, done / total,
         screenshot ? " -> " : "", screenshot ? screenshot : "");
  return 0;
}

int cmd_view(int argc, char **argv) {
  cli_args a;
  int rc = cli_args_parse(CLI_VIEW, argc, argv, 1, &a);
  if (rc) {
    if (rc == CLI_HELP_SHOWN) fputs(keys_help, stdout);
    return rc == CLI_HELP_SHOWN ? 0 : rc;
  }
  if ((rc = cli_scene_file_defaults(&a))) return rc;
  const char *scene = a.pos[0];
  int threads = omp_get_num_procs(), shade = 0, set = 0, trace = 0, denoise = 1, temporal = 1, frames = 0;
  float turntable = 0.0f;
  int filter = 1;
  static const char *const sets[] = {"cells", "spread"};
  cli_view v;
  cli_whitted wo;
  cli_path po;
  if ((rc = cli_view_from_args(&a, &v)) || (rc = cli_whitted_from_args(&a, &wo)) || (rc = cli_path_from_args(&a, &po)) ||
      (rc = cli_common_from_args(&a, &threads)) ||
      (rc = cli_arg_choice(&a, F_SHADE, fr_shade_mode_names, FR_SM_COUNT, &shade)) ||
      (rc = cli_arg_choice(&a, F_LIGHT_SETS, sets, 2, &set)) || (rc = cli_arg_onoff(&a, F_FILTER, &filter)) ||
      (rc = cli_arg_choice(&a, F_MODE, view_trace_names, VIEW_TRACE_COUNT, &trace)) ||
      (rc = cli_arg_onoff(&a, F_DENOISE, &denoise)) || (rc = cli_arg_onoff(&a, F_TEMPORAL, &temporal)) ||
      (rc = cli_arg_int(&a, F_FRAMES, 1, 1000000, &frames)) ||
      (rc = cli_arg_float(&a, F_TURNTABLE, -180.0f, 180.0f, &turntable)))
    return rc;
  if (!scene) return cli_error(CLI_USAGE_ERROR, "usage: frusta view SCENE|--builtin [flags] (see frusta view --help)");
  if (!a.val[F_SIZE]) v.width = 1024, v.height = 768;
  if (!a.val[F_SPP]) po.spp = 1024;
  if (!a.val[F_SAMPLER]) po.sampler = FR_SAMPLER_SOBOL;
  if (shade == FR_SM_AO && po.spp % 16)
    return cli_error(CLI_USAGE_ERROR, "ao: --spp wants a multiple of 16 (hemisphere rays per pixel), got '%s'", a.val[F_SPP]);
  const char *screenshot = a.val[F_SCREENSHOT];
  if (screenshot && !fr_image_format_known(screenshot))
    return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", screenshot);
  if ((a.val[F_CAMERA_PATH] || a.val[F_TURNTABLE] || screenshot) && !frames && !a.val[F_CAMERA_PATH])
    return cli_error(CLI_USAGE_ERROR, "--turntable and --screenshot go with --frames N (or --camera-path)");
  view_camera *path = NULL;
  size_t npath = 0;
  if (a.val[F_CAMERA_PATH] && (rc = view_camera_path_read(a.val[F_CAMERA_PATH], &path, &npath))) return rc;
  if (npath && !frames) frames = npath > 1000000 ? 1000000 : (int)npath;

  /* the display first: without one there is nothing to do. SDL falls back
   * to drivers that show nothing (offscreen, dummy); those only when asked
   * for by SDL_VIDEODRIVER. */
  const char *asked = getenv("SDL_VIDEODRIVER");
  if (!(asked && *asked) && !getenv("WAYLAND_DISPLAY")) SDL_SetHint(SDL_HINT_VIDEODRIVER, "x11"); /* no Wayland probe and its stderr line */
  const int sdl_ok = SDL_Init(SDL_INIT_VIDEO) == 0;
  const char *driver = sdl_ok ? SDL_GetCurrentVideoDriver() : NULL;
  if (!sdl_ok || !driver || ((!strcmp(driver, "offscreen") || !strcmp(driver, "dummy")) && !(asked && *asked))) {
    free(path);
    rc = cli_error(1, "view: cannot open a window (no display: DISPLAY is %s%s%s)", getenv("DISPLAY") ? getenv("DISPLAY") : "unset",
                   sdl_ok ? "" : "; ", sdl_ok ? "" : SDL_GetError());
    SDL_Quit();
    return rc;
  }
  view_app app;
  memset(&app, 0, sizeof app);
  fr_scene *s = NULL;
  fr_workload w;
  memset(&w, 0, sizeof w);
  if ((rc = cli_workload_setup(scene, &v, threads, &s, &w))) goto done;
  w.seed = 1;
  app.scene_name = cli_scene_name(s);
  if (a.val[F_RECORD] && !(app.record = fopen(a.val[F_RECORD], "w"))) {
    rc = cli_error(1, "%s: cannot write the camera path", a.val[F_RECORD]);
    goto done;
  }
  view_settings init = {{w.view.eye, w.view.at, w.view.up, w.view.fov}, v.width, v.height, (fr_shade_mode)shade,
                        (view_trace)trace, denoise, temporal};
  if ((rc = view_renderer_init(&app.r, s, &w.view, &po, &wo, filter, set ? FR_LIGHT_SETS_SPREAD : FR_LIGHT_SETS_CELLS,
                               threads, &init)))
    goto done;
  pthread_mutex_init(&app.sh.lock, NULL);
  pthread_cond_init(&app.sh.wake, NULL);
  pthread_cond_init(&app.sh.ready, NULL);
  app.win = SDL_CreateWindow("frusta", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, v.width, v.height,
                             frames ? 0 : SDL_WINDOW_RESIZABLE);
  if (app.win) app.ren = SDL_CreateRenderer(app.win, -1, 0);
  if (!app.win || !app.ren) { rc = cli_error(1, "view: cannot open a window: %s", SDL_GetError()); goto done; }
  if (frames) rc = run_frames(&app, init, frames, path, npath, turntable, screenshot);
  else rc = run_interactive(&app, init, 0.25f * v3_len(v3_sub(s->bounds.hi, s->bounds.lo)));
done:
  if (app.record && fclose(app.record) && !rc) rc = cli_error(1, "%s: cannot write the camera path", a.val[F_RECORD]);
  if (app.tex) SDL_DestroyTexture(app.tex);
  if (app.ren) SDL_DestroyRenderer(app.ren);
  if (app.win) SDL_DestroyWindow(app.win);
  view_renderer_free(&app.r);
  free(app.sh.frame);
  if (s) fr_scene_release(s);
  free(path);
  SDL_Quit();
  return rc;
}
