/* Compiled mirrors of per-step hot loops (see visuomotor_gym/_native/__init__.py).
 *
 * Every kernel mirrors one Python function, named in its comment, operation for operation: the same
 * additions and products in the same order, the same comparisons, libm's sqrt/sin/cos/atan2/pow (the
 * functions Python's math module and float ** call). Built with -ffp-contract=off (no fused
 * multiply-adds) and -fno-builtin (no sin+cos -> sincos, pow(x, 2) -> x*x), so the results are the
 * Python path's bit for bit; tests/test_native.py and the golden digests check it. Python's
 * math.hypot is not libm's hypot: it is called through the math module.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>

static PyObject *math_hypot;  /* math.hypot */
/* attribute names, interned once */
static PyObject *s_time, *s_suppressed, *s_prev_request, *s_last_sample, *s_drive_queue, *s_drive, *s_goal,
    *s_pursuit_omega, *s_saccade, *s_omega, *s_onset, *s_duration, *s_amplitude, *s_arc, *s_axis, *s_gaze,
    *s_hidden, *s_state, *s_last_onset, *s_standard_normal, *s_kind, *s_group, *s_name, *s_values;
static PyObject *np_empty, *np_ndarray, *np_float32, *int_three; /* numpy.empty, .ndarray, .float32, 3 */
static PyObject *np_float64_dtype, *s_dtype, *float_zero; /* numpy.dtype("float64"), "dtype" */


/* ---- small helpers -------------------------------------------------------------------------- */

/* n doubles from a tuple or list of floats. */
static int seq_doubles(PyObject *seq, double *out, Py_ssize_t n)
{
    if (!(PyTuple_Check(seq) || PyList_Check(seq)) || PySequence_Fast_GET_SIZE(seq) != n) {
        PyErr_Format(PyExc_TypeError, "expected a tuple or list of %zd floats", n);
        return -1;
    }
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(items[i]);
        if (out[i] == -1.0 && PyErr_Occurred())
            return -1;
    }
    return 0;
}

/* Whether ``obj`` is a numpy array (not a subclass) of native float64. */
static int is_f64_array(PyObject *obj)
{
    if (Py_TYPE(obj) != (PyTypeObject *)np_ndarray)
        return 0;
    PyObject *dtype = PyObject_GetAttr(obj, s_dtype);
    if (dtype == NULL) {
        PyErr_Clear();
        return 0;
    }
    int same = dtype == np_float64_dtype;
    if (!same) { /* an equal but distinct descriptor */
        same = PyObject_RichCompareBool(dtype, np_float64_dtype, Py_EQ);
        if (same < 0) {
            PyErr_Clear();
            same = 0;
        }
    }
    Py_DECREF(dtype);
    return same;
}

/* A C-contiguous float64 buffer of a numpy array; the caller releases the view. (The dtype is
 * checked first: numpy's buffer export is cheaper without a format string.) */
static int f64_buffer(PyObject *obj, Py_buffer *view, int writable)
{
    if (!is_f64_array(obj)) {
        PyErr_SetString(PyExc_TypeError, "expected a float64 numpy array");
        return -1;
    }
    return PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0));
}

/* n doubles from a float64 array starting at element `start`. */
static int array_doubles(PyObject *obj, Py_ssize_t start, double *out, Py_ssize_t n)
{
    Py_buffer view;
    if (f64_buffer(obj, &view, 0) < 0)
        return -1;
    if (start < 0 || (start + n) * 8 > view.len) {
        PyBuffer_Release(&view);
        PyErr_SetString(PyExc_IndexError, "array too short");
        return -1;
    }
    memcpy(out, (double *)view.buf + start, (size_t)n * sizeof(double));
    PyBuffer_Release(&view);
    return 0;
}

static PyObject *tuple3(double x, double y, double z)
{
    PyObject *fx = PyFloat_FromDouble(x), *fy = PyFloat_FromDouble(y), *fz = PyFloat_FromDouble(z);
    PyObject *out = (fx && fy && fz) ? PyTuple_Pack(3, fx, fy, fz) : NULL;
    Py_XDECREF(fx);
    Py_XDECREF(fy);
    Py_XDECREF(fz);
    return out;
}

/* ``np.array([x, y, z])`` (a new float64 array), made as np.empty(3) and filled. */
static PyObject *array3(double x, double y, double z)
{
    PyObject *out = PyObject_CallOneArg(np_empty, int_three);
    if (out == NULL)
        return NULL;
    Py_buffer view;
    if (f64_buffer(out, &view, 1) < 0) {
        Py_DECREF(out);
        return NULL;
    }
    double *v = (double *)view.buf;
    v[0] = x, v[1] = y, v[2] = z;
    PyBuffer_Release(&view);
    return out;
}

static PyObject *list_of(const double *v, Py_ssize_t n)
{
    PyObject *out = PyList_New(n);
    if (out == NULL)
        return NULL;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *f = PyFloat_FromDouble(v[i]);
        if (f == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, i, f);
    }
    return out;
}

/* Python's min(a, b) and max(a, b) for floats: the first argument unless the second is strictly
 * smaller (larger); NaN and signed zeros behave as in Python. */
static inline double py_min(double a, double b) { return b < a ? b : a; }
static inline double py_max(double a, double b) { return b > a ? b : a; }

static int set_attr_double(PyObject *obj, PyObject *name, double v)
{
    PyObject *f = PyFloat_FromDouble(v);
    if (f == NULL)
        return -1;
    int rc = PyObject_SetAttr(obj, name, f);
    Py_DECREF(f);
    return rc;
}

static int get_attr_double(PyObject *obj, PyObject *name, double *out)
{
    PyObject *v = PyObject_GetAttr(obj, name);
    if (v == NULL)
        return -1;
    *out = PyFloat_AsDouble(v);
    Py_DECREF(v);
    return (*out == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

/* A 3-vector: a tuple or list of floats, a float64 array read directly, another array through .tolist(). */
static int vec3(PyObject *obj, double *out)
{
    if (PyTuple_Check(obj) || PyList_Check(obj))
        return seq_doubles(obj, out, 3);
    Py_buffer view;
    if (is_f64_array(obj)) {
        if (PyObject_GetBuffer(obj, &view, PyBUF_C_CONTIGUOUS) == 0) {
            int ok = view.len == 24;
            if (ok)
                memcpy(out, view.buf, 3 * sizeof(double));
            PyBuffer_Release(&view);
            if (ok)
                return 0;
        } else {
            PyErr_Clear();
        }
    }
    PyObject *list = PyObject_CallMethod(obj, "tolist", NULL);
    if (list == NULL)
        return -1;
    int rc = seq_doubles(list, out, 3);
    Py_DECREF(list);
    return rc;
}

/* ---- the oculomotor plant (visuomotor_gym/oculomotor/plant.py) -------------------------------- */

/* The plant's constants, packed by OculomotorPlant._native_constants:
 * [saccade threshold (rad), pursuit latency (s), pursuit acceleration bound (rad/s^2),
 *  pursuit cap (deg/s), DEG, saccade refractory period (s), number of gain points, then
 *  (deg/s, gain) pairs]. */
typedef struct {
    double threshold, latency, accel, vmax, deg, refractory;
    Py_ssize_t npts;
    const double *pts;
} PlantConsts;

static int plant_consts(PyObject *packed, PlantConsts *c)
{
    if (!PyBytes_Check(packed) || PyBytes_GET_SIZE(packed) < 7 * 8) {
        PyErr_SetString(PyExc_TypeError, "plant constants: expected the packed bytes");
        return -1;
    }
    const double *v = (const double *)PyBytes_AS_STRING(packed);
    c->threshold = v[0];
    c->latency = v[1];
    c->accel = v[2];
    c->vmax = v[3];
    c->deg = v[4];
    c->refractory = v[5];
    c->npts = (Py_ssize_t)v[6];
    c->pts = v + 7;
    if (c->npts < 1 || PyBytes_GET_SIZE(packed) != (7 + 2 * c->npts) * 8) {
        PyErr_SetString(PyExc_ValueError, "plant constants: bad size");
        return -1;
    }
    return 0;
}

/* OculomotorParams.pursuit_gain */
static double pursuit_gain(const PlantConsts *c, double s)
{
    const double *p = c->pts;
    if (s <= p[0])
        return p[1];
    for (Py_ssize_t k = 0; k + 1 < c->npts; k++) {
        double s0 = p[2 * k], g0 = p[2 * k + 1], s1 = p[2 * k + 2], g1 = p[2 * k + 3];
        if (s <= s1)
            return g0 + (g1 - g0) * (s - s0) / (s1 - s0);
    }
    return p[2 * c->npts - 1];
}

/* OculomotorParams.pursuit_velocity */
static double pursuit_velocity(const PlantConsts *c, double s) { return py_min(pursuit_gain(c, s) * s, c->vmax); }

/* The drive queue's head time, or inf (``queue[0][0] if queue else math.inf``). */
static int queue_due(PyObject *queue, double *due)
{
    if (PyList_GET_SIZE(queue) == 0) {
        *due = INFINITY;
        return 0;
    }
    PyObject *head = PyList_GET_ITEM(queue, 0);
    if (!PyTuple_Check(head) || PyTuple_GET_SIZE(head) != 4) {
        PyErr_SetString(PyExc_TypeError, "drive queue entries must be (time, wx, wy, wz)");
        return -1;
    }
    *due = PyFloat_AsDouble(PyTuple_GET_ITEM(head, 0));
    return (*due == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

/* The pursuit state the substep loop carries: the drive sample driving the eye and its goal. */
typedef struct {
    double drive[3];
    double goal[3];
    int goal_zero; /* ``goal is _ZERO`` */
    int changed;   /* _pursuit_goal set a new drive and goal (else the plant keeps its objects) */
} Pursuit;

/* OculomotorPlant._pursuit_goal(t) */
static int pursuit_goal(const PlantConsts *c, PyObject *queue, Pursuit *ps, double t)
{
    double due;
    if (queue_due(queue, &due) < 0)
        return -1;
    if (PyList_GET_SIZE(queue) == 0 || due > t + 1e-9)
        return 0;
    while (PyList_GET_SIZE(queue) > 0) {
        if (queue_due(queue, &due) < 0)
            return -1;
        if (!(due <= t + 1e-9))
            break;
        double entry[4];
        if (seq_doubles(PyList_GET_ITEM(queue, 0), entry, 4) < 0)
            return -1;
        ps->drive[0] = entry[1];
        ps->drive[1] = entry[2];
        ps->drive[2] = entry[3];
        if (PyList_SetSlice(queue, 0, 1, NULL) < 0) /* queue.pop(0) */
            return -1;
    }
    ps->changed = 1;
    double wx = ps->drive[0], wy = ps->drive[1], wz = ps->drive[2];
    double speed = sqrt(wx * wx + wy * wy + wz * wz);
    if (speed < 1e-12) {
        ps->goal_zero = 1;
        ps->goal[0] = ps->goal[1] = ps->goal[2] = 0.0;
    } else {
        double k = pursuit_velocity(c, speed / c->deg) * c->deg / speed;
        ps->goal_zero = 0;
        ps->goal[0] = wx * k;
        ps->goal[1] = wy * k;
        ps->goal[2] = wz * k;
    }
    return 0;
}

/* OculomotorPlant._sample_target_motion(target, dt) */
static int sample_target_motion(PyObject *plant, const PlantConsts *c, PyObject *queue, PyObject *request,
                                const double *b, double dt, int suppressed, double now)
{
    PyObject *prev = PyObject_GetAttr(plant, s_prev_request);
    if (prev == NULL)
        return -1;
    PyObject *sample = PyObject_GetAttr(plant, s_last_sample); /* held without a motion signal */
    if (sample == NULL) {
        Py_DECREF(prev);
        return -1;
    }
    double a[3];
    if (prev != Py_None && !suppressed) {
        if (seq_doubles(prev, a, 3) < 0)
            goto fail;
        double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
        double s = sqrt(cx * cx + cy * cy + cz * cz);
        double jump = atan2(s, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]); /* geometry.angle_between */
        if (jump <= c->threshold) {
            double k = s > 1e-15 ? jump / dt / s : 0.0;
            Py_DECREF(sample);
            sample = tuple3(cx * k, cy * k, cz * k);
            if (sample == NULL)
                goto fail;
        }
    }
    double smp[3];
    if (seq_doubles(sample, smp, 3) < 0 || PyObject_SetAttr(plant, s_last_sample, sample) < 0
        || PyObject_SetAttr(plant, s_prev_request, request) < 0)
        goto fail;
    PyObject *entry = Py_BuildValue("(dddd)", now + c->latency, smp[0], smp[1], smp[2]);
    if (entry == NULL || PyList_Append(queue, entry) < 0) {
        Py_XDECREF(entry);
        goto fail;
    }
    Py_DECREF(entry);
    Py_DECREF(prev);
    Py_DECREF(sample);
    return 0;
fail:
    Py_DECREF(prev);
    Py_XDECREF(sample);
    return -1;
}

/* The saccade in flight: Saccade.onset, duration, amplitude and its arc (start, tangent). */
typedef struct {
    double onset, duration, amplitude, a[3], w[3];
} Flight;

static int read_saccade(PyObject *sac, Flight *f)
{
    if (get_attr_double(sac, s_onset, &f->onset) < 0 || get_attr_double(sac, s_duration, &f->duration) < 0
        || get_attr_double(sac, s_amplitude, &f->amplitude) < 0)
        return -1;
    PyObject *arc = PyObject_GetAttr(sac, s_arc);
    if (arc == NULL)
        return -1;
    int rc = -1;
    if (PyTuple_Check(arc) && PyTuple_GET_SIZE(arc) == 2)
        rc = (seq_doubles(PyTuple_GET_ITEM(arc, 0), f->a, 3) < 0 || seq_doubles(PyTuple_GET_ITEM(arc, 1), f->w, 3) < 0)
                 ? -1 : 0;
    else
        PyErr_SetString(PyExc_TypeError, "Saccade._arc must be (start, tangent)");
    Py_DECREF(arc);
    return rc;
}

/* Saccade.direction(minimum_jerk(u)) */
static void saccade_point(const Flight *f, double u, double *g)
{
    double s_u = u * u * u * (10.0 + u * (-15.0 + 6.0 * u)); /* minimum_jerk */
    double t = s_u * f->amplitude;
    double c = cos(t), s = sin(t);
    g[0] = c * f->a[0] + s * f->w[0];
    g[1] = c * f->a[1] + s * f->w[1];
    g[2] = c * f->a[2] + s * f->w[2];
}

/* The part of OculomotorPlant.step after the saccade decision, for record=False: the target-motion
 * sample (_sample_target_motion), the substep loop (pursuit velocity with _pursuit_goal, the saccade
 * profile, the Rodrigues rotation) and the end-of-step state, read from and written to the plant's
 * attributes as the Python does. ``zero`` is plant.py's _ZERO, the goal the Python compares by
 * identity. Returns ``saccading`` (0/1), or -1 with an exception set. */
static int plant_advance(PyObject *plant, const PlantConsts *cp, PyObject *request, const double *req, double dt,
                         long n_substeps, PyObject *zero)
{
    const PlantConsts c = *cp;
    PyObject *queue = NULL, *goal_obj = NULL, *sac = NULL, *tmp = NULL;
    int result = -1;
    double t0, g[3], v[3];
    Pursuit ps;
    Flight f;
    int suppressed;
    if ((tmp = PyObject_GetAttr(plant, s_suppressed)) == NULL || (suppressed = PyObject_IsTrue(tmp)) < 0)
        goto done;
    Py_CLEAR(tmp);
    if (get_attr_double(plant, s_time, &t0) < 0 || (queue = PyObject_GetAttr(plant, s_drive_queue)) == NULL)
        goto done;
    if (!PyList_CheckExact(queue)) {
        PyErr_SetString(PyExc_TypeError, "plant._drive_queue must be a list");
        goto done;
    }
    if (sample_target_motion(plant, &c, queue, request, req, dt, suppressed, t0) < 0)
        goto done;

    ps.drive[0] = ps.drive[1] = ps.drive[2] = 0.0; /* _pursuit_goal sets it before any use */
    if ((goal_obj = PyObject_GetAttr(plant, s_goal)) == NULL || seq_doubles(goal_obj, ps.goal, 3) < 0)
        goto done;
    ps.goal_zero = goal_obj == zero;
    ps.changed = 0;
    if ((tmp = PyObject_GetAttr(plant, s_pursuit_omega)) == NULL || seq_doubles(tmp, v, 3) < 0)
        goto done;
    Py_CLEAR(tmp);
    if ((tmp = PyObject_GetAttr(plant, s_gaze)) == NULL || array_doubles(tmp, 0, g, 3) < 0)
        goto done;
    Py_CLEAR(tmp);
    if ((sac = PyObject_GetAttr(plant, s_saccade)) == NULL)
        goto done;
    int saccading = sac != Py_None;
    int in_flight = saccading; /* the loop's ``sac is not None`` */
    if (saccading && read_saccade(sac, &f) < 0)
        goto done;

    /* --- the substep loop of OculomotorPlant.step --- */
    double h = dt / n_substeps;
    double a_max = c.accel * h; /* c.accel = pursuit_accel_max_deg_s2 * DEG */
    double vx = v[0], vy = v[1], vz = v[2], gx = g[0], gy = g[1], gz = g[2];
    int in_saccade_last = 0;
    double due;
    if (queue_due(queue, &due) < 0)
        goto done;
    int still = ps.goal_zero && vx == 0.0 && vy == 0.0 && vz == 0.0;
    for (long i = 1; i <= n_substeps; i++) {
        double t = t0 + h * (double)i;
        if (due <= (t - h) + 1e-9) {
            if (pursuit_goal(&c, queue, &ps, t - h) < 0 || queue_due(queue, &due) < 0)
                goto done;
            still = ps.goal_zero && vx == 0.0 && vy == 0.0 && vz == 0.0;
        }
        if (!still) {
            double ex = ps.goal[0] - vx, ey = ps.goal[1] - vy, ez = ps.goal[2] - vz;
            double e = sqrt(ex * ex + ey * ey + ez * ez);
            if (e > a_max) {
                ex = ex * a_max / e;
                ey = ey * a_max / e;
                ez = ez * a_max / e;
            }
            vx = vx + ex;
            vy = vy + ey;
            vz = vz + ez;
            still = ps.goal_zero && vx == 0.0 && vy == 0.0 && vz == 0.0;
        }
        if (in_flight) {
            double u = (t - f.onset) / f.duration;
            if (u >= 1.0)
                u = 1.0;
            else if (u < 0.0)
                u = 0.0;
            in_saccade_last = u < 1.0;
            if (u >= 1.0 || i == n_substeps) {
                double p[3];
                saccade_point(&f, u, p);
                gx = p[0];
                gy = p[1];
                gz = p[2];
            }
            if (u >= 1.0)
                in_flight = 0;
        } else if (!still) {
            in_saccade_last = 0;
            double d = vx * gx + vy * gy + vz * gz;
            double wx = vx - d * gx, wy = vy - d * gy, wz = vz - d * gz;
            double w = sqrt(wx * wx + wy * wy + wz * wz);
            if (w > 1e-15) {
                double ang = w * h;
                double co = cos(ang), si = sin(ang);
                double kx = wx / w, ky = wy / w, kz = wz / w;
                double cx = ky * gz - kz * gy, cy = kz * gx - kx * gz, cz = kx * gy - ky * gx;
                gx = co * gx + si * cx;
                gy = co * gy + si * cy;
                gz = co * gz + si * cz;
                double m = sqrt(gx * gx + gy * gy + gz * gz);
                gx = gx / m;
                gy = gy / m;
                gz = gz / m;
            }
        } else {
            in_saccade_last = 0;
        }
    }

    /* --- the end of OculomotorPlant.step: angular velocity, state --- */
    PyObject *omega = NULL;
    if (saccading && in_saccade_last) {
        double u = py_min(py_max((t0 + dt - f.onset) / f.duration, 0.0), 1.0);
        double speed = f.amplitude * 30.0 * pow(u, 2.0) * pow(1.0 - u, 2.0) / f.duration; /* Eq. 15 */
        PyObject *axis = PyObject_GetAttr(sac, s_axis);
        if (axis == NULL)
            goto done;
        omega = Py_BuildValue("(ONd)", Py_None, axis, speed);
    } else {
        if (saccading && PyObject_SetAttr(plant, s_saccade, Py_None) < 0)
            goto done;
        double d = vx * gx + vy * gy + vz * gz;
        omega = Py_BuildValue("(N(ddd)d)", Py_NewRef(Py_None), vx - d * gx, vy - d * gy, vz - d * gz, 1.0);
    }
    if (omega == NULL)
        goto done;
    int rc = PyObject_SetAttr(plant, s_omega, omega);
    Py_DECREF(omega);
    if (rc < 0)
        goto done;
    if (ps.changed) { /* the drive and goal _pursuit_goal left */
        if ((tmp = tuple3(ps.drive[0], ps.drive[1], ps.drive[2])) == NULL || PyObject_SetAttr(plant, s_drive, tmp) < 0)
            goto done;
        Py_CLEAR(tmp);
        if (ps.goal_zero)
            tmp = Py_NewRef(zero);
        else
            tmp = tuple3(ps.goal[0], ps.goal[1], ps.goal[2]);
        if (tmp == NULL || PyObject_SetAttr(plant, s_goal, tmp) < 0)
            goto done;
        Py_CLEAR(tmp);
    }
    if ((tmp = tuple3(vx, vy, vz)) == NULL || PyObject_SetAttr(plant, s_pursuit_omega, tmp) < 0)
        goto done;
    Py_CLEAR(tmp);
    if (PyObject_SetAttr(plant, s_suppressed, saccading ? Py_True : Py_False) < 0
        || set_attr_double(plant, s_time, t0 + dt) < 0)
        goto done;
    /* self.gaze = np.array([gx, gy, gz]) */
    if ((tmp = array3(gx, gy, gz)) == NULL || PyObject_SetAttr(plant, s_gaze, tmp) < 0)
        goto done;
    result = saccading;
done:
    Py_XDECREF(queue);
    Py_XDECREF(goal_obj);
    Py_XDECREF(sac);
    Py_XDECREF(tmp);
    return result;
}


/* The start of OculomotorPlant.step, then plant_advance: the request normalised, and the saccade
 * decision. Returns 0 (stepped; *saccading and *deferred set), 1 when a saccade starts now (nothing
 * was changed: the caller runs the Python step, which builds the Saccade), -1 on error. */
static int plant_step_impl(PyObject *plant, const PlantConsts *c, const double *target, double dt, long n_substeps,
                           PyObject *zero, int *saccading, int *deferred)
{
    double tx = target[0], ty = target[1], tz = target[2];
    double n = sqrt(tx * tx + ty * ty + tz * tz);
    double req[3] = {tx / n, ty / n, tz / n};
    *deferred = 0;
    PyObject *sac = PyObject_GetAttr(plant, s_saccade);
    if (sac == NULL)
        return -1;
    int idle = sac == Py_None;
    Py_DECREF(sac);
    if (idle) {
        double g[3], now, last;
        PyObject *gaze = PyObject_GetAttr(plant, s_gaze);
        if (gaze == NULL)
            return -1;
        int rc = array_doubles(gaze, 0, g, 3);
        Py_DECREF(gaze);
        if (rc < 0)
            return -1;
        /* geometry.angle_between(self.gaze, request) */
        double cx = g[1] * req[2] - g[2] * req[1], cy = g[2] * req[0] - g[0] * req[2], cz = g[0] * req[1] - g[1] * req[0];
        double amplitude = atan2(sqrt(cx * cx + cy * cy + cz * cz), g[0] * req[0] + g[1] * req[1] + g[2] * req[2]);
        if (amplitude > c->threshold) {
            if (get_attr_double(plant, s_time, &now) < 0 || get_attr_double(plant, s_last_onset, &last) < 0)
                return -1;
            if (now - last >= c->refractory - 1e-9) /* ready_for_saccade */
                return 1;
            *deferred = 1; /* waits for the generator; not executed as pursuit */
        }
    }
    PyObject *request = tuple3(req[0], req[1], req[2]);
    if (request == NULL)
        return -1;
    *saccading = plant_advance(plant, c, request, req, dt, n_substeps, zero);
    Py_DECREF(request);
    return *saccading < 0 ? -1 : 0;
}

/* plant_step(plant, target, dt, n_substeps, constants, zero) -> (saccading, deferred) or None
 *
 * OculomotorPlant.step for record=False, except a step that starts a saccade: None, and nothing
 * changed (the Python step runs it). ``target``: a 3-tuple of floats or a float64 array. */
static PyObject *plant_step(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 6) {
        PyErr_SetString(PyExc_TypeError, "plant_step(plant, target, dt, n_substeps, constants, zero)");
        return NULL;
    }
    PlantConsts c;
    double target[3];
    double dt = PyFloat_AsDouble(args[2]);
    long n_substeps = PyLong_AsLong(args[3]);
    if ((dt == -1.0 || n_substeps == -1) && PyErr_Occurred())
        return NULL;
    if (plant_consts(args[4], &c) < 0)
        return NULL;
    if ((PyTuple_Check(args[1]) ? seq_doubles(args[1], target, 3) : vec3(args[1], target)) < 0)
        return NULL;
    int saccading, deferred;
    int rc = plant_step_impl(args[0], &c, target, dt, n_substeps, args[5], &saccading, &deferred);
    if (rc < 0)
        return NULL;
    if (rc == 1)
        Py_RETURN_NONE;
    return Py_BuildValue("(OO)", saccading ? Py_True : Py_False, deferred ? Py_True : Py_False);
}

/* ---- the eye (visuomotor_gym/core/eye.py) ----------------------------------------------------- */

/* eye_command(rot_flat, plant, plant constants, zero, eye constants, g_az, g_el, g_fix, dt, n_substeps,
 *             fixation) -> (saccading, deferred, fixation) or None
 *
 * Mirrors Eye.command: the requested gaze (unit_from_angles in the eye frame, rotated to the world),
 * the plant's step (plant_step: None when a saccade starts, nothing changed, and the caller runs the
 * Python method) and the rate-limited vergence. ``eye constants`` = (gaze action range, log of the
 * fixation range's ends, vergence rate limit). */
static PyObject *eye_command(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 11) {
        PyErr_SetString(PyExc_TypeError, "eye_command(rot_flat, plant, plant_constants, zero, eye_constants, "
                                         "g_az, g_el, g_fix, dt, n_substeps, fixation)");
        return NULL;
    }
    double r[9], ec[4];
    PlantConsts c;
    double g_az = PyFloat_AsDouble(args[5]), g_el = PyFloat_AsDouble(args[6]), g_fix = PyFloat_AsDouble(args[7]);
    double dt = PyFloat_AsDouble(args[8]), fixation = PyFloat_AsDouble(args[10]);
    long n_substeps = PyLong_AsLong(args[9]);
    if (PyErr_Occurred() || seq_doubles(args[0], r, 9) < 0 || plant_consts(args[2], &c) < 0
        || seq_doubles(args[4], ec, 4) < 0)
        return NULL;
    /* geometry.unit_from_angles, then geometry.rotate(self.rot_flat, *u) */
    double az = g_az * ec[0], el = g_el * ec[0];
    double ce = cos(el);
    double ux = ce * cos(az), uy = ce * sin(az), uz = sin(el);
    double target[3] = {r[0] * ux + r[1] * uy + r[2] * uz, r[3] * ux + r[4] * uy + r[5] * uz,
                        r[6] * ux + r[7] * uy + r[8] * uz};
    int saccading, deferred;
    int rc = plant_step_impl(args[1], &c, target, dt, n_substeps, args[3], &saccading, &deferred);
    if (rc < 0)
        return NULL;
    if (rc == 1)
        Py_RETURN_NONE;
    double lo = ec[1], hi = ec[2];
    double fix_target = exp(lo + (g_fix + 1.0) * 0.5 * (hi - lo));
    double vergence = ec[3] * dt; /* rate limit in diopters */
    double inv = py_min(py_max(1.0 / fix_target, 1.0 / fixation - vergence), 1.0 / fixation + vergence);
    return Py_BuildValue("(OOd)", saccading ? Py_True : Py_False, deferred ? Py_True : Py_False, 1.0 / inv);
}

/* eye_apply(xmat, xpos, head_body, gaze, offset, ranges, qpos, qvel, addresses, fixation)
 *   -> (rot_flat, pos_list, (az, el), clamped)
 *
 * Mirrors Eye.apply (the vestibulo-ocular reflex): the world gaze in head coordinates, the clamped
 * eye-in-head angles, the eye frame (head rotation @ Rz(az) Ry(-el)) and the eye's centre; writes
 * the eye joints into qpos (the clamped angles, the fixation) and zeros their qvel.
 * ``ranges`` = (az_lo, az_hi, el_lo, el_hi); ``addresses`` = (qpos az, qpos el, qpos fixation,
 * dof az, dof el). The caller hands a clamped gaze to OculomotorPlant.constrain. */
static PyObject *eye_apply(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 10) {
        PyErr_SetString(PyExc_TypeError,
                        "eye_apply(xmat, xpos, head_body, gaze, offset, ranges, qpos, qvel, addresses, fixation)");
        return NULL;
    }
    Py_ssize_t body = PyLong_AsSsize_t(args[2]);
    double fixation = PyFloat_AsDouble(args[9]);
    if ((body == -1 || fixation == -1.0) && PyErr_Occurred())
        return NULL;
    double hm[9], hp[3], gw[3], off[3], rng[4], adr[5];
    if (array_doubles(args[0], 9 * body, hm, 9) < 0 || array_doubles(args[1], 3 * body, hp, 3) < 0
        || array_doubles(args[3], 0, gw, 3) < 0 || seq_doubles(args[4], off, 3) < 0
        || seq_doubles(args[5], rng, 4) < 0 || seq_doubles(args[8], adr, 5) < 0)
        return NULL;
    double h0 = hm[0], h1 = hm[1], h2 = hm[2], h3 = hm[3], h4 = hm[4], h5 = hm[5], h6 = hm[6], h7 = hm[7],
           h8 = hm[8];
    /* geometry.rotate_t(head, *gaze) */
    double gx = h0 * gw[0] + h3 * gw[1] + h6 * gw[2];
    double gy = h1 * gw[0] + h4 * gw[1] + h7 * gw[2];
    double gz = h2 * gw[0] + h5 * gw[1] + h8 * gw[2];
    double az = atan2(gy, gx);
    PyObject *hyp = PyObject_CallFunction(math_hypot, "dd", gx, gy);
    if (hyp == NULL)
        return NULL;
    double hxy = PyFloat_AsDouble(hyp);
    Py_DECREF(hyp);
    if (hxy == -1.0 && PyErr_Occurred())
        return NULL;
    double el = atan2(gz, hxy);
    double az_c = py_min(py_max(az, rng[0]), rng[1]);
    double el_c = py_min(py_max(el, rng[2]), rng[3]);
    double ca = cos(az_c), sa = sin(az_c), ce = cos(el_c), se = sin(el_c);
    double e00 = ca * ce, e01 = -sa, e02 = -ca * se, e10 = sa * ce, e11 = ca, e12 = -sa * se, e20 = se, e22 = ce;
    double flat[9] = {
        h0 * e00 + h1 * e10 + h2 * e20, h0 * e01 + h1 * e11, h0 * e02 + h1 * e12 + h2 * e22,
        h3 * e00 + h4 * e10 + h5 * e20, h3 * e01 + h4 * e11, h3 * e02 + h4 * e12 + h5 * e22,
        h6 * e00 + h7 * e10 + h8 * e20, h6 * e01 + h7 * e11, h6 * e02 + h7 * e12 + h8 * e22,
    };
    int clamped = az_c != az || el_c != el;
    /* geometry.rotate(head, *offset) */
    double ox = h0 * off[0] + h1 * off[1] + h2 * off[2];
    double oy = h3 * off[0] + h4 * off[1] + h5 * off[2];
    double oz = h6 * off[0] + h7 * off[1] + h8 * off[2];
    double pos[3] = {hp[0] + ox, hp[1] + oy, hp[2] + oz};

    Py_buffer qp, qv;
    if (f64_buffer(args[6], &qp, 1) < 0)
        return NULL;
    if (f64_buffer(args[7], &qv, 1) < 0) {
        PyBuffer_Release(&qp);
        return NULL;
    }
    Py_ssize_t nq = qp.len / 8, nv = qv.len / 8;
    Py_ssize_t ia = (Py_ssize_t)adr[0], ie = (Py_ssize_t)adr[1], ifx = (Py_ssize_t)adr[2], da = (Py_ssize_t)adr[3],
               de = (Py_ssize_t)adr[4];
    int ok = ia >= 0 && ia < nq && ie >= 0 && ie < nq && ifx >= 0 && ifx < nq && da >= 0 && da < nv && de >= 0
             && de < nv;
    if (ok) {
        double *q = (double *)qp.buf, *qd = (double *)qv.buf;
        q[ia] = az_c;
        q[ie] = el_c;
        q[ifx] = fixation;
        qd[da] = 0.0;
        qd[de] = 0.0;
    }
    PyBuffer_Release(&qp);
    PyBuffer_Release(&qv);
    if (!ok) {
        PyErr_SetString(PyExc_IndexError, "eye_apply: joint address out of range");
        return NULL;
    }
    return Py_BuildValue("(NN(dd)O)", list_of(flat, 9), list_of(pos, 3), az_c, el_c, clamped ? Py_True : Py_False);
}

/* ---- the retina (visuomotor_gym/core/retina.py, vision/foveation.py) --------------------------- */

/* The vision constants, packed by Retina._native_constants (see there for the order). */
typedef struct {
    double foveated, cos_fov, fov, noise_scale, pos_std_arcmin, arcmin, weber, floor, depth, depth_rate, e2, knee;
} VisionConsts;

/* A sample: ([px, py, pz], [vx, vy, vz], visible), built directly (cheaper than Py_BuildValue). */
static PyObject *sample_of(const double *p, const double *v, int visible)
{
    PyObject *pos = list_of(p, 3), *vel = list_of(v, 3);
    PyObject *out = (pos && vel) ? PyTuple_Pack(3, pos, vel, visible ? Py_True : Py_False) : NULL;
    Py_XDECREF(pos);
    Py_XDECREF(vel);
    return out;
}

/* retina.nothing(): new lists holding one shared 0.0 (as the Python's literal constants do) */
static PyObject *nothing(void)
{
    PyObject *pos = PyList_New(3), *vel = PyList_New(3);
    PyObject *out = (pos && vel) ? PyTuple_Pack(3, pos, vel, Py_False) : NULL;
    for (int i = 0; out != NULL && i < 3; i++) {
        PyList_SET_ITEM(pos, i, Py_NewRef(float_zero));
        PyList_SET_ITEM(vel, i, Py_NewRef(float_zero));
    }
    Py_XDECREF(pos);
    Py_XDECREF(vel);
    return out;
}

/* Eye.retinal_speed; ``eye`` = the eye's pos_list, prev_pos, prev_gaze and rot_flat, in that order. */
static double retinal_speed(const double *eye, double rx, double ry, double rz, double vx, double vy, double vz,
                            double dt)
{
    const double *e = eye, *p = eye + 3, *a = eye + 6, *r = eye + 9;
    double inv_dt = 1.0 / dt;
    double ux = vx - (e[0] - p[0]) / dt, uy = vy - (e[1] - p[1]) / dt, uz = vz - (e[2] - p[2]) / dt;
    double r0 = r[0], r3 = r[3], r6 = r[6];
    double wx = (a[1] * r6 - a[2] * r3) * inv_dt, wy = (a[2] * r0 - a[0] * r6) * inv_dt,
           wz = (a[0] * r3 - a[1] * r0) * inv_dt;
    double dist2 = rx * rx + ry * ry + rz * rz;
    double sx = (ry * uz - rz * uy) / dist2 - wx;
    double sy = (rz * ux - rx * uz) / dist2 - wy;
    double sz = (rx * uy - ry * ux) / dist2 - wz;
    double along = (sx * rx + sy * ry + sz * rz) / dist2;
    sx = sx - along * rx;
    sy = sy - along * ry;
    sz = sz - along * rz;
    return sqrt(sx * sx + sy * sy + sz * sz);
}

/* foveation._sigmas (with acuity and slip_factor) */
static void sigmas(const VisionConsts *c, double distance, double ecc, double speed, double *s)
{
    double alpha = c->foveated ? c->e2 / (c->e2 + ecc) : 1.0;                    /* acuity */
    double slip = c->foveated ? py_max(1.0, fabs(speed) / c->knee) : 1.0;        /* slip_factor */
    double k = distance * c->noise_scale / alpha;
    double lateral = k * c->pos_std_arcmin * c->arcmin * slip;
    double lateral_rate = k * (c->weber * fabs(speed) + c->floor);
    s[0] = k * c->depth;
    s[1] = lateral;
    s[2] = lateral;
    s[3] = k * c->depth_rate;
    s[4] = lateral_rate;
    s[5] = lateral_rate;
}

/* foveation._los_rows */
static void los_rows(double ux, double uy, double uz, double *r)
{
    double c = ux;
    if (c < -1.0 + 1e-12) {
        const double behind[9] = {-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0};
        memcpy(r, behind, sizeof(behind));
        return;
    }
    double f = 1.0 / (1.0 + c);
    r[0] = c, r[1] = -uy, r[2] = -uz;
    r[3] = uy, r[4] = 1.0 - f * uy * uy, r[5] = -f * uy * uz;
    r[6] = uz, r[7] = -f * uy * uz, r[8] = 1.0 - f * uz * uz;
}

/* One target's look, between foveation.perceive's checks and _draw_at's noise. */
typedef struct {
    int kind; /* 0: not seen (nothing()), 1: at the eye's centre (the true state), 2: seen, noise to draw */
    double p[3], v[3], s[6], r[9];
} Look;

/* foveation.perceive up to the draw: the field-of-view check, then _sigmas and _los_rows. */
static void perceive_prepare(const VisionConsts *c, const double *pe, const double *ve, double speed, Look *lk)
{
    double x = pe[0], y = pe[1], z = pe[2];
    memcpy(lk->p, pe, sizeof(lk->p));
    memcpy(lk->v, ve, sizeof(lk->v));
    double d = sqrt(x * x + y * y + z * z);
    if (d <= 0.0) {
        lk->kind = 1;
        return;
    }
    double ecc = acos(py_max(-1.0, py_min(1.0, x / d)));
    if (c->foveated && ecc > c->fov) {
        lk->kind = 0;
        return;
    }
    lk->kind = 2;
    sigmas(c, d, ecc, speed, lk->s);
    los_rows(x / d, y / d, z / d, lk->r);
}

/* The sample of a look (foveation._draw_at with the six standard normals ``e``). */
/* rng.standard_normal(6 n) (one six-vector per look, in look order) into *draw (a new reference) and
 * *normals (its buffer, held): 0; -1 with an exception set and *normals not held (buf NULL). */
static int draw_normals(PyObject *rng, Py_ssize_t n, PyObject **draw, Py_buffer *normals)
{
    PyObject *size = PyLong_FromSsize_t(6 * n);
    if (size == NULL)
        return -1;
    PyObject *call[2] = {rng, size};
    *draw = PyObject_VectorcallMethod(s_standard_normal, call, 2 | PY_VECTORCALL_ARGUMENTS_OFFSET, NULL);
    Py_DECREF(size);
    if (*draw == NULL || f64_buffer(*draw, normals, 0) < 0) {
        normals->buf = NULL;
        return -1;
    }
    if (normals->len != 48 * n) {
        PyBuffer_Release(normals);
        normals->buf = NULL;
        PyErr_SetString(PyExc_ValueError, "rng.standard_normal gave the wrong size");
        return -1;
    }
    return 0;
}

/* A VisualTarget's world position b and velocity v (its ``state(data)``): 1 when shown, 0 when hidden
 * (b, v untouched), -1 with an exception set. */
static int target_state(PyObject *target, PyObject *data, double *b, double *v)
{
    PyObject *hidden = PyObject_GetAttr(target, s_hidden);
    if (hidden == NULL)
        return -1;
    int is_hidden = PyObject_IsTrue(hidden);
    Py_DECREF(hidden);
    if (is_hidden != 0)
        return is_hidden < 0 ? -1 : 0;
    PyObject *state = PyObject_CallMethodOneArg(target, s_state, data);
    if (state == NULL)
        return -1;
    int rc = -1;
    if (PyTuple_Check(state) && PyTuple_GET_SIZE(state) == 2)
        rc = (vec3(PyTuple_GET_ITEM(state, 0), b) < 0 || vec3(PyTuple_GET_ITEM(state, 1), v) < 0) ? -1 : 0;
    else
        PyErr_SetString(PyExc_TypeError, "VisualTarget.state must return (position, velocity)");
    Py_DECREF(state);
    return rc < 0 ? -1 : 1;
}

static PyObject *look_sample(const Look *lk, const double *e)
{
    if (lk->kind == 0)
        return nothing();
    if (lk->kind == 1)
        return sample_of(lk->p, lk->v, 1);
    const double *s = lk->s, *r = lk->r, *p = lk->p, *v = lk->v;
    double n0 = s[0] * e[0], n1 = s[1] * e[1], n2 = s[2] * e[2], n3 = s[3] * e[3], n4 = s[4] * e[4], n5 = s[5] * e[5];
    double pos[3] = {p[0] + r[0] * n0 + r[1] * n1 + r[2] * n2, p[1] + r[3] * n0 + r[4] * n1 + r[5] * n2,
                     p[2] + r[6] * n0 + r[7] * n1 + r[8] * n2};
    double vel[3] = {v[0] + r[0] * n3 + r[1] * n4 + r[2] * n5, v[1] + r[3] * n3 + r[4] * n4 + r[5] * n5,
                     v[2] + r[6] * n3 + r[7] * n4 + r[8] * n5};
    return sample_of(pos, vel, 1);
}

/* retina_see_all(targets, data, eye, dt, constants, rng) -> [sample per target]
 *
 * Mirrors Retina._see_all: for each target, nothing() when hidden or outside the field of view,
 * else its position and velocity in the eye frame, the retinal slip (Eye.retinal_speed) and one
 * noisy look (foveation.perceive). The Python draws rng.standard_normal(6) per seen target, in
 * target order; this draws the same numbers in one rng.standard_normal(6 k) for the k seen targets
 * (numpy's Generator fills an array one normal after the other: the same stream, checked by
 * tests/test_native.py). ``eye`` = pos_list + prev_pos + prev_gaze + rot_flat (18 floats). */
static PyObject *retina_see_all(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 6) {
        PyErr_SetString(PyExc_TypeError, "retina_see_all(targets, data, eye, dt, constants, rng)");
        return NULL;
    }
    PyObject *targets = args[0], *data = args[1], *rng = args[5];
    double eye[18];
    double dt = PyFloat_AsDouble(args[3]);
    if (dt == -1.0 && PyErr_Occurred())
        return NULL;
    if (seq_doubles(args[2], eye, 18) < 0)
        return NULL;
    if (!PyBytes_Check(args[4]) || PyBytes_GET_SIZE(args[4]) != sizeof(VisionConsts)) {
        PyErr_SetString(PyExc_TypeError, "retina_see_all: bad vision constants");
        return NULL;
    }
    VisionConsts c;
    memcpy(&c, PyBytes_AS_STRING(args[4]), sizeof(VisionConsts));
    const double *r = eye + 9;
    PyObject *seq = PySequence_Fast(targets, "targets must be a sequence");
    if (seq == NULL)
        return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq), seen = 0;
    PyObject *out = NULL, *draw = NULL;
    Look *looks = PyMem_Malloc((size_t)(n > 0 ? n : 1) * sizeof(Look));
    if (looks == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    for (Py_ssize_t i = 0; i < n; i++) { /* every target up to its noise draw */
        PyObject *target = PySequence_Fast_GET_ITEM(seq, i);
        Look *lk = &looks[i];
        lk->kind = 0;
        double b[3], v[3];
        int shown = target_state(target, data, b, v);
        if (shown < 0)
            goto fail;
        if (!shown)
            continue;
        double rx = b[0] - eye[0], ry = b[1] - eye[1], rz = b[2] - eye[2];
        double px = r[0] * rx + r[3] * ry + r[6] * rz;
        if (c.foveated && px < c.cos_fov * sqrt(rx * rx + ry * ry + rz * rz))
            continue; /* outside the field of view */
        double pe[3] = {px, r[1] * rx + r[4] * ry + r[7] * rz, r[2] * rx + r[5] * ry + r[8] * rz};
        double ve[3] = {r[0] * v[0] + r[3] * v[1] + r[6] * v[2], r[1] * v[0] + r[4] * v[1] + r[7] * v[2],
                        r[2] * v[0] + r[5] * v[1] + r[8] * v[2]};
        perceive_prepare(&c, pe, ve, retinal_speed(eye, rx, ry, rz, v[0], v[1], v[2], dt), lk);
        seen += lk->kind == 2;
    }
    const double *e = NULL;
    Py_buffer normals = {.buf = NULL};
    if (seen > 0) {
        if (draw_normals(rng, seen, &draw, &normals) < 0)
            goto fail;
        e = (const double *)normals.buf;
    }
    out = PyList_New(n);
    for (Py_ssize_t i = 0; out != NULL && i < n; i++) {
        PyObject *sample = look_sample(&looks[i], e);
        if (sample == NULL) {
            Py_CLEAR(out);
            break;
        }
        PyList_SET_ITEM(out, i, sample);
        if (looks[i].kind == 2)
            e += 6;
    }
    if (seen > 0)
        PyBuffer_Release(&normals);
    if (out == NULL)
        goto fail;
    Py_XDECREF(draw);
    PyMem_Free(looks);
    Py_DECREF(seq);
    return out;
fail:
    Py_XDECREF(draw);
    PyMem_Free(looks);
    Py_DECREF(seq);
    return NULL;
}

/* ---- the human periphery (visuomotor_gym/vision/periphery.py, Retina._see_all_periphery) -------- */

/* The periphery's constants, packed by retina.periphery_constants (see there for the order). Angles
 * are already in radians, computed there as the Python computes them (``field_side_deg * DEG`` ...). */
typedef struct {
    double foveated, human, fov, side, up, down, crowding, crowd_fovea, bouma, pos_e2_on, pos_e2, e2,
        noise_scale, pos_std_arcmin, arcmin, knee, weber, floor, depth, depth_rate, pedestal_on, pedestal,
        interocular, disarray;
} PeripheryConsts;

static int periphery_consts(PyObject *packed, PeripheryConsts *c)
{
    if (!PyBytes_Check(packed) || PyBytes_GET_SIZE(packed) != sizeof(PeripheryConsts)) {
        PyErr_SetString(PyExc_TypeError, "periphery constants: expected retina.periphery_constants(params)");
        return -1;
    }
    memcpy(c, PyBytes_AS_STRING(packed), sizeof(PeripheryConsts));
    return 0;
}

/* periphery.human_field_limit */
static double human_field_limit(const PeripheryConsts *c, double uy, double uz)
{
    double s = c->side;
    double v = uz >= 0.0 ? c->up : c->down;
    double rho2 = uy * uy + uz * uz;
    if (rho2 <= 0.0)
        return s;
    return 1.0 / sqrt((uy * uy / rho2) / (s * s) + (uz * uz / rho2) / (v * v));
}

/* periphery.in_field */
static int in_field(const PeripheryConsts *c, double x, double y, double z)
{
    if (!c->foveated)
        return 1;
    double d = sqrt(x * x + y * y + z * z);
    if (d <= 0.0)
        return 1;
    double ecc = acos(py_max(-1.0, py_min(1.0, x / d)));
    if (c->human)
        return ecc <= human_field_limit(c, y / d, z / d);
    return ecc <= c->fov;
}

/* periphery.position_factor */
static double position_factor(const PeripheryConsts *c, double ecc)
{
    if (!c->foveated)
        return 1.0;
    return 1.0 + ecc / c->pos_e2;
}

/* periphery.depth_factor; ``has_fixation`` false: fixation is None. */
static double depth_factor(const PeripheryConsts *c, double distance, int has_fixation, double fixation)
{
    if (!c->pedestal_on || !c->foveated || !has_fixation || distance <= 0.0)
        return 1.0;
    double eta = c->interocular * fabs(1.0 / distance - 1.0 / fixation);
    return 1.0 + eta / c->pedestal;
}

/* foveation._sigmas with params.periphery_on (acuity, slip_factor, the position and depth laws) */
static void periphery_sigmas(const PeripheryConsts *c, double distance, double ecc, double speed, int has_fixation,
                             double fixation, double *s)
{
    double alpha = c->foveated ? c->e2 / (c->e2 + ecc) : 1.0;                /* acuity */
    double slip = c->foveated ? py_max(1.0, fabs(speed) / c->knee) : 1.0;    /* slip_factor */
    double k = distance * c->noise_scale / alpha;
    double lateral = k * c->pos_std_arcmin * c->arcmin * slip;
    double lateral_rate = k * (c->weber * fabs(speed) + c->floor);
    if (c->pos_e2_on)
        lateral = distance * c->noise_scale * position_factor(c, ecc) * c->pos_std_arcmin * c->arcmin * slip;
    double g = depth_factor(c, distance, has_fixation, fixation);
    s[0] = k * c->depth * g;
    s[1] = lateral;
    s[2] = lateral;
    s[3] = k * c->depth_rate * g;
    s[4] = lateral_rate;
    s[5] = lateral_rate;
}

/* periphery.angular_separation */
static double angular_separation(const double *u, const double *v)
{
    double cx = u[1] * v[2] - u[2] * v[1];
    double cy = u[2] * v[0] - u[0] * v[2];
    double cz = u[0] * v[1] - u[1] * v[0];
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), u[0] * v[0] + u[1] * v[1] + u[2] * v[2]);
}

/* Class labels of ``items`` by equality: label[k] = the first k' <= k with items[k'] == items[k], found
 * through a dict (a kind or an object is a str: hash and == agree, as in crowding_groups' dict). */
static int labels_of(PyObject *const *items, Py_ssize_t n, Py_ssize_t *label)
{
    PyObject *first = PyDict_New();
    if (first == NULL)
        return -1;
    for (Py_ssize_t k = 0; k < n; k++) {
        PyObject *index = PyLong_FromSsize_t(k);
        PyObject *got = index == NULL ? NULL : PyDict_SetDefault(first, items[k], index);
        Py_XDECREF(index);
        if (got == NULL) {
            Py_DECREF(first);
            return -1;
        }
        label[k] = PyLong_AsSsize_t(got); /* borrowed, held by the dict */
    }
    Py_DECREF(first);
    return 0;
}

/* periphery.crowding_groups for target i, on C arrays: ``dirs`` n x 3, ``eccs`` n, ``kind`` and ``obj``
 * the labels (labels_of) of the targets' kinds and objects. Writes elem[j] = the element of i's group
 * that holds j (1, 2, ...: the flanking objects in order of first appearance), 0 for none (i's own
 * element [i] is element 0), and returns the number of elements (1: i alone). ``slot`` (n entries,
 * all -1 on entry and on return): an object label's element. */
static Py_ssize_t crowd_one(const PeripheryConsts *c, Py_ssize_t n, Py_ssize_t i, const double *dirs,
                            const double *eccs, const Py_ssize_t *kind, const Py_ssize_t *obj, Py_ssize_t *elem,
                            Py_ssize_t *slot)
{
    memset(elem, 0, (size_t)n * sizeof(Py_ssize_t));
    if (!(c->crowding && c->foveated))
        return 1;
    double theta = eccs[i];
    if (theta <= c->crowd_fovea)
        return 1;
    double spacing = c->bouma * theta;
    Py_ssize_t m = 1;
    for (Py_ssize_t j = 0; j < n; j++) {
        if (j != i && kind[j] == kind[i] && obj[j] != obj[i]
            && angular_separation(dirs + 3 * i, dirs + 3 * j) < spacing) {
            if (slot[obj[j]] < 0)
                slot[obj[j]] = m++;
            elem[j] = slot[obj[j]];
        }
    }
    for (Py_ssize_t j = 0; j < n; j++)
        if (elem[j])
            slot[obj[j]] = -1;
    return m;
}

/* periphery.pooled over ``vecs`` (n x 3) of target i's group (crowd_one's elem and m) into out[3]: each
 * element's sum runs over its points in index order from 0.0, as the Python's does. ``acc``: 4 m
 * doubles of scratch. */
static void pool_one(Py_ssize_t n, Py_ssize_t i, const Py_ssize_t *elem, Py_ssize_t m, const double *vecs,
                     double *acc, double *out)
{
    if (m == 1) { /* a lone target is itself */
        memcpy(out, vecs + 3 * i, 3 * sizeof(double));
        return;
    }
    for (Py_ssize_t e = 0; e < 4 * m; e++)
        acc[e] = 0.0;
    acc[0] += vecs[3 * i], acc[1] += vecs[3 * i + 1], acc[2] += vecs[3 * i + 2], acc[3] = 1.0; /* [i] */
    for (Py_ssize_t j = 0; j < n; j++) {
        if (elem[j] == 0)
            continue;
        double *a = acc + 4 * elem[j];
        const double *v = vecs + 3 * j;
        a[0] += v[0];
        a[1] += v[1];
        a[2] += v[2];
        a[3] += 1.0;
    }
    double sx = 0.0, sy = 0.0, sz = 0.0;
    for (Py_ssize_t e = 0; e < m; e++) {
        const double *a = acc + 4 * e;
        sx += a[0] / a[3];
        sy += a[1] / a[3];
        sz += a[2] / a[3];
    }
    out[0] = sx / (double)m, out[1] = sy / (double)m, out[2] = sz / (double)m;
}

/* n x 3 doubles from a sequence of 3-sequences (lists, tuples or arrays) into a new buffer. */
static double *rows3(PyObject *seq, Py_ssize_t n)
{
    double *out = PyMem_Malloc((size_t)(n > 0 ? 3 * n : 1) * sizeof(double));
    if (out == NULL) {
        PyErr_NoMemory();
        return NULL;
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        if (vec3(PySequence_Fast_GET_ITEM(seq, k), out + 3 * k) < 0) {
            PyMem_Free(out);
            return NULL;
        }
    }
    return out;
}

/* Scratch arrays of crowd_one and pool_one for n targets, in one allocation (slot all -1). */
typedef struct {
    Py_ssize_t *kind, *obj, *elem, *slot;
    double *acc;
} Crowd;

static int crowd_alloc(Crowd *w, Py_ssize_t n)
{
    size_t m = (size_t)(n > 0 ? n : 1);
    w->kind = PyMem_Malloc(4 * m * sizeof(Py_ssize_t) + 4 * m * sizeof(double));
    if (w->kind == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    w->obj = w->kind + m, w->elem = w->obj + m, w->slot = w->elem + m, w->acc = (double *)(w->slot + m);
    for (size_t k = 0; k < m; k++)
        w->slot[k] = -1;
    return 0;
}

/* crowding_groups(directions, eccentricities, kinds, objects, constants) -> groups
 *
 * periphery.crowding_groups: the same groups (lists of lists of ints) for the same arguments, the
 * params given as retina.periphery_constants(params). */
static PyObject *crowding_groups(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "crowding_groups(directions, eccentricities, kinds, objects, constants)");
        return NULL;
    }
    PeripheryConsts c;
    if (periphery_consts(args[4], &c) < 0)
        return NULL;
    PyObject *dseq = NULL, *eseq = NULL, *kseq = NULL, *oseq = NULL, *out = NULL;
    double *dirs = NULL, *eccs = NULL;
    Crowd w = {NULL};
    dseq = PySequence_Fast(args[0], "directions must be a sequence");
    eseq = dseq ? PySequence_Fast(args[1], "eccentricities must be a sequence") : NULL;
    kseq = eseq ? PySequence_Fast(args[2], "kinds must be a sequence") : NULL;
    oseq = kseq ? PySequence_Fast(args[3], "objects must be a sequence") : NULL;
    if (oseq == NULL)
        goto done;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(dseq);
    if (PySequence_Fast_GET_SIZE(eseq) != n || PySequence_Fast_GET_SIZE(kseq) != n
        || PySequence_Fast_GET_SIZE(oseq) != n) {
        PyErr_SetString(PyExc_ValueError, "crowding_groups: directions, eccentricities, kinds and objects "
                                          "must have the same length");
        goto done;
    }
    if ((dirs = rows3(dseq, n)) == NULL || crowd_alloc(&w, n) < 0)
        goto done;
    eccs = PyMem_Malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    if (eccs == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        eccs[k] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(eseq, k));
        if (eccs[k] == -1.0 && PyErr_Occurred())
            goto done;
    }
    if (labels_of(PySequence_Fast_ITEMS(kseq), n, w.kind) < 0
        || labels_of(PySequence_Fast_ITEMS(oseq), n, w.obj) < 0)
        goto done;
    out = PyList_New(n);
    for (Py_ssize_t i = 0; out != NULL && i < n; i++) {
        Py_ssize_t m = crowd_one(&c, n, i, dirs, eccs, w.kind, w.obj, w.elem, w.slot);
        PyObject *group = PyList_New(m);
        int ok = group != NULL;
        for (Py_ssize_t e = 0; ok && e < m; e++) {
            PyObject *element = PyList_New(0);
            ok = element != NULL;
            if (ok)
                PyList_SET_ITEM(group, e, element);
        }
        for (Py_ssize_t k = 0; ok && k < n; k++) { /* [i], then each flanking object's points in index order */
            if (k != i && w.elem[k] == 0)
                continue;
            PyObject *index = PyLong_FromSsize_t(k);
            ok = index != NULL && PyList_Append(PyList_GET_ITEM(group, k == i ? 0 : w.elem[k]), index) == 0;
            Py_XDECREF(index);
        }
        if (!ok) {
            Py_XDECREF(group);
            Py_CLEAR(out);
            break;
        }
        PyList_SET_ITEM(out, i, group);
    }
done:
    PyMem_Free(dirs);
    PyMem_Free(eccs);
    PyMem_Free(w.kind);
    Py_XDECREF(dseq);
    Py_XDECREF(eseq);
    Py_XDECREF(kseq);
    Py_XDECREF(oseq);
    return out;
}

/* pooled(vectors, group) -> [x, y, z]: periphery.pooled (a group as crowding_groups gives it). */
static PyObject *pooled(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "pooled(vectors, group)");
        return NULL;
    }
    PyObject *group = PySequence_Fast(args[1], "group must be a sequence");
    if (group == NULL)
        return NULL;
    PyObject *vectors = args[0], *out = NULL;
    Py_ssize_t m = PySequence_Fast_GET_SIZE(group);
    double sx = 0.0, sy = 0.0, sz = 0.0, v[3];
    for (Py_ssize_t e = 0; e < m; e++) {
        PyObject *element = PySequence_Fast(PySequence_Fast_GET_ITEM(group, e), "a group's element must be a sequence");
        if (element == NULL)
            goto done;
        Py_ssize_t members = PySequence_Fast_GET_SIZE(element);
        double ex = 0.0, ey = 0.0, ez = 0.0;
        for (Py_ssize_t q = 0; q < members; q++) {
            PyObject *vec = PyObject_GetItem(vectors, PySequence_Fast_GET_ITEM(element, q));
            int rc = vec == NULL ? -1 : vec3(vec, v);
            Py_XDECREF(vec);
            if (rc < 0) {
                Py_DECREF(element);
                goto done;
            }
            if (m == 1 && members == 1) { /* a lone target is itself */
                Py_DECREF(element);
                out = list_of(v, 3);
                goto done;
            }
            ex += v[0];
            ey += v[1];
            ez += v[2];
        }
        Py_DECREF(element);
        if (members == 0) {
            PyErr_SetString(PyExc_ZeroDivisionError, "pooled: an empty element");
            goto done;
        }
        sx += ex / (double)members;
        sy += ey / (double)members;
        sz += ez / (double)members;
    }
    if (m == 0) {
        PyErr_SetString(PyExc_ZeroDivisionError, "pooled: an empty group");
        goto done;
    }
    v[0] = sx / (double)m, v[1] = sy / (double)m, v[2] = sz / (double)m;
    out = list_of(v, 3);
done:
    Py_DECREF(group);
    return out;
}

/* The per-seen-target state of retina_see_periphery. */
typedef struct {
    Py_ssize_t index;        /* the target's index */
    double p[3], v[3];       /* position and velocity, eye frame (pooled once crowding is applied) */
    double slip, d, ecc;     /* retinal speed; the look's distance and eccentricity */
} Seen;

/* A float64 array's element [row, col] of a 2-D strided buffer. */
static double at2(const Py_buffer *view, Py_ssize_t row, Py_ssize_t col)
{
    return *(const double *)((const char *)view->buf + row * view->strides[0] + col * view->strides[1]);
}

/* retina_see_periphery(targets, data, eye, dt, constants, rng, fixation, disarray) -> [sample per target]
 *
 * Mirrors Retina._see_all_periphery (``constants`` = retina.periphery_constants(params); ``eye`` as for
 * retina_see_all; ``fixation`` the eye's vergence distance or None; ``disarray`` the retina's
 * DisarrayField or None): every target's position, velocity and retinal slip in the eye frame when it
 * is shown and in the field (periphery.in_field), crowding and pooling (crowding_groups, pooled), each
 * look's distance and eccentricity, the disarray field's values at every look in one call of
 * ``disarray.values`` (numpy's own arithmetic), then foveation._draw_at. The Python draws
 * rng.standard_normal(6) per look at a point off the eye's centre, in target order; this draws them in
 * one rng.standard_normal(6 k) (the same stream, tests/test_native.py). */
static PyObject *retina_see_periphery(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError,
                        "retina_see_periphery(targets, data, eye, dt, constants, rng, fixation, disarray)");
        return NULL;
    }
    PyObject *targets = args[0], *data = args[1], *rng = args[5], *disarray = args[7];
    double eye[18], fixation = 0.0;
    int has_fixation = args[6] != Py_None;
    double dt = PyFloat_AsDouble(args[3]);
    if (dt == -1.0 && PyErr_Occurred())
        return NULL;
    if (has_fixation) {
        fixation = PyFloat_AsDouble(args[6]);
        if (fixation == -1.0 && PyErr_Occurred())
            return NULL;
    }
    if (seq_doubles(args[2], eye, 18) < 0)
        return NULL;
    PeripheryConsts c;
    if (periphery_consts(args[4], &c) < 0)
        return NULL;
    const double *r = eye + 9;
    PyObject *seq = PySequence_Fast(targets, "targets must be a sequence");
    if (seq == NULL)
        return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq), m = 0, draws = 0;
    PyObject *out = NULL, *draw = NULL, *fixed = NULL, **labels = NULL;
    Py_buffer normals = {.buf = NULL}, fixed_view = {.buf = NULL};
    double *dirs = NULL, *pooled_v = NULL;
    Crowd w = {NULL};
    Seen *seen = PyMem_Malloc((size_t)(n > 0 ? n : 1) * sizeof(Seen));
    if (seen == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    for (Py_ssize_t i = 0; i < n; i++) { /* every shown target in the field */
        PyObject *target = PySequence_Fast_GET_ITEM(seq, i);
        double b[3], v[3];
        int shown = target_state(target, data, b, v);
        if (shown < 0)
            goto fail;
        if (!shown)
            continue;
        double rx = b[0] - eye[0], ry = b[1] - eye[1], rz = b[2] - eye[2];
        double pe[3] = {r[0] * rx + r[3] * ry + r[6] * rz, r[1] * rx + r[4] * ry + r[7] * rz,
                        r[2] * rx + r[5] * ry + r[8] * rz};
        if (!in_field(&c, pe[0], pe[1], pe[2]))
            continue;
        Seen *s = &seen[m++];
        s->index = i;
        memcpy(s->p, pe, sizeof(pe));
        s->v[0] = r[0] * v[0] + r[3] * v[1] + r[6] * v[2];
        s->v[1] = r[1] * v[0] + r[4] * v[1] + r[7] * v[2];
        s->v[2] = r[2] * v[0] + r[5] * v[1] + r[8] * v[2];
        /* pos_eye[0] ** 2 + ...: Python's float ** 2 is libm's pow (of |x|: float_pow) */
        s->d = sqrt(pow(fabs(pe[0]), 2.0) + pow(fabs(pe[1]), 2.0) + pow(fabs(pe[2]), 2.0));
        if (rx * rx + ry * ry + rz * rz == 0.0) { /* Eye.retinal_speed divides by it */
            PyErr_SetString(PyExc_ZeroDivisionError, "float division by zero");
            goto fail;
        }
        s->slip = retinal_speed(eye, rx, ry, rz, v[0], v[1], v[2], dt);
    }
    if (c.crowding && m > 1) { /* crowding: each seen target at the mean of its group */
        dirs = PyMem_Malloc((size_t)(16 * m) * sizeof(double)); /* dirs, eccs, pooled p and v, unpooled */
        labels = PyMem_Malloc((size_t)(2 * m) * sizeof(PyObject *));
        if (dirs == NULL || labels == NULL) {
            PyErr_NoMemory();
            goto fail;
        }
        memset(labels, 0, (size_t)(2 * m) * sizeof(PyObject *));
        double *eccs = dirs + 3 * m;
        pooled_v = eccs + m;
        if (crowd_alloc(&w, m) < 0)
            goto fail;
        for (Py_ssize_t k = 0; k < m; k++) {
            const Seen *s = &seen[k];
            double *u = dirs + 3 * k;
            if (s->d > 0.0)
                u[0] = s->p[0] / s->d, u[1] = s->p[1] / s->d, u[2] = s->p[2] / s->d;
            else
                u[0] = 1.0, u[1] = 0.0, u[2] = 0.0;
            eccs[k] = acos(py_max(-1.0, py_min(1.0, u[0])));
            PyObject *target = PySequence_Fast_GET_ITEM(seq, s->index);
            if ((labels[k] = PyObject_GetAttr(target, s_kind)) == NULL)
                goto fail;
            PyObject *group = PyObject_GetAttr(target, s_group);
            if (group == NULL)
                goto fail;
            if (group == Py_None) {
                Py_DECREF(group);
                if ((group = PyObject_GetAttr(target, s_name)) == NULL)
                    goto fail;
            }
            labels[m + k] = group;
        }
        if (labels_of(labels, m, w.kind) < 0 || labels_of(labels + m, m, w.obj) < 0)
            goto fail;
        double *pv = pooled_v; /* m pooled positions, then m pooled velocities */
        double *src = dirs + 4 * m + 6 * m; /* the unpooled positions, then velocities */
        for (Py_ssize_t k = 0; k < m; k++) {
            memcpy(src + 3 * k, seen[k].p, 3 * sizeof(double));
            memcpy(src + 3 * (m + k), seen[k].v, 3 * sizeof(double));
        }
        for (Py_ssize_t k = 0; k < m; k++) {
            Py_ssize_t count = crowd_one(&c, m, k, dirs, eccs, w.kind, w.obj, w.elem, w.slot);
            pool_one(m, k, w.elem, count, src, w.acc, pv + 3 * k);
            pool_one(m, k, w.elem, count, src + 3 * m, w.acc, pv + 3 * (m + k));
        }
        for (Py_ssize_t k = 0; k < m; k++) {
            memcpy(seen[k].p, pv + 3 * k, 3 * sizeof(double));
            memcpy(seen[k].v, pv + 3 * (m + k), 3 * sizeof(double));
        }
    }
    for (Py_ssize_t k = 0; k < m; k++) { /* the looks */
        Seen *s = &seen[k];
        double x = s->p[0], y = s->p[1], z = s->p[2];
        s->d = sqrt(x * x + y * y + z * z);
        s->ecc = s->d > 0.0 ? acos(py_max(-1.0, py_min(1.0, x / s->d))) : 0.0;
        draws += s->d > 0.0;
    }
    if (disarray != Py_None && m > 0) { /* disarray.values(eccentricities, polar angles) */
        PyObject *eccs = PyList_New(m), *phis = PyList_New(m);
        for (Py_ssize_t k = 0; eccs != NULL && phis != NULL && k < m; k++) {
            PyObject *e = PyFloat_FromDouble(seen[k].ecc), *a = PyFloat_FromDouble(atan2(seen[k].p[2], seen[k].p[1]));
            if (e == NULL || a == NULL) {
                Py_XDECREF(e);
                Py_XDECREF(a);
                Py_CLEAR(eccs);
                break;
            }
            PyList_SET_ITEM(eccs, k, e);
            PyList_SET_ITEM(phis, k, a);
        }
        if (eccs != NULL && phis != NULL)
            fixed = PyObject_CallMethodObjArgs(disarray, s_values, eccs, phis, NULL);
        Py_XDECREF(eccs);
        Py_XDECREF(phis);
        if (fixed == NULL)
            goto fail;
        if (!is_f64_array(fixed) || PyObject_GetBuffer(fixed, &fixed_view, PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
            fixed_view.buf = NULL;
            if (!PyErr_Occurred())
                PyErr_SetString(PyExc_TypeError, "disarray.values must return a float64 array");
            goto fail;
        }
        if (fixed_view.ndim != 2 || fixed_view.shape[0] != 2 || fixed_view.shape[1] != m) {
            PyBuffer_Release(&fixed_view);
            fixed_view.buf = NULL;
            PyErr_SetString(PyExc_ValueError, "disarray.values must return an array of shape (2, n)");
            goto fail;
        }
    }
    const double *e = NULL;
    if (draws > 0) {
        if (draw_normals(rng, draws, &draw, &normals) < 0)
            goto fail;
        e = (const double *)normals.buf;
    }
    out = PyList_New(n);
    if (out == NULL)
        goto fail;
    for (Py_ssize_t k = 0, i = 0; i < n; i++) {
        PyObject *sample;
        if (k < m && seen[k].index == i) {
            const Seen *s = &seen[k];
            if (s->d <= 0.0) { /* at the eye's centre: the (pooled) state itself */
                sample = sample_of(s->p, s->v, 1);
            } else { /* foveation._draw_at */
                Look lk = {.kind = 2};
                double eps[6];
                memcpy(eps, e, sizeof(eps));
                e += 6;
                if (fixed != NULL) {
                    double f = position_factor(&c, s->ecc);
                    double wgt = c.disarray * (1.0 - 1.0 / (f * f)); /* periphery.disarray_weight */
                    double a = sqrt(wgt), b = sqrt(1.0 - wgt);
                    double f0 = at2(&fixed_view, 0, k), f1 = at2(&fixed_view, 1, k);
                    eps[1] = a * f0 + b * eps[1];
                    eps[2] = a * f1 + b * eps[2];
                }
                memcpy(lk.p, s->p, sizeof(lk.p));
                memcpy(lk.v, s->v, sizeof(lk.v));
                periphery_sigmas(&c, s->d, s->ecc, s->slip, has_fixation, fixation, lk.s);
                los_rows(s->p[0] / s->d, s->p[1] / s->d, s->p[2] / s->d, lk.r);
                sample = look_sample(&lk, eps);
            }
            k++;
        } else {
            sample = nothing();
        }
        if (sample == NULL) {
            Py_CLEAR(out);
            goto fail;
        }
        PyList_SET_ITEM(out, i, sample);
    }
fail:
    if (normals.buf != NULL)
        PyBuffer_Release(&normals);
    if (fixed_view.buf != NULL)
        PyBuffer_Release(&fixed_view);
    Py_XDECREF(fixed);
    Py_XDECREF(draw);
    if (labels != NULL)
        for (Py_ssize_t k = 0; k < 2 * m; k++)
            Py_XDECREF(labels[k]);
    PyMem_Free(labels);
    PyMem_Free(dirs);
    PyMem_Free(w.kind);
    PyMem_Free(seen);
    Py_DECREF(seq);
    return out;
}

/* ---- the hand (visuomotor_gym/control/hand.py) ---------------------------------------------------
 * HandController.setpoints keeps its three matrix products (numpy's BLAS, whose summation order C
 * cannot reproduce); these kernels do the element-wise work around them, into arrays the controller
 * allocated. */

/* Float64 buffers for a kernel: up to 12, writable ones flagged; all released by release_all. */
typedef struct {
    Py_buffer view[12];
    int n;
} Buffers;

static double *buf(Buffers *b, PyObject *obj, int writable, Py_ssize_t min_len)
{
    if (b->n >= (int)(sizeof(b->view) / sizeof(b->view[0]))) {
        PyErr_SetString(PyExc_RuntimeError, "too many buffers");
        return NULL;
    }
    if (f64_buffer(obj, &b->view[b->n], writable) < 0)
        return NULL;
    Py_buffer *v = &b->view[b->n++];
    if (v->len / 8 < min_len) {
        PyErr_SetString(PyExc_IndexError, "array too short");
        return NULL;
    }
    return (double *)v->buf;
}

static void release_all(Buffers *b)
{
    for (int i = 0; i < b->n; i++)
        PyBuffer_Release(&b->view[i]);
    b->n = 0;
}

/* hand_advance(reference, target, max_speed, dt) -> new reference (an array)
 *
 * Mirrors HandController.advance_reference: the reference moved toward ``target`` by at most
 * ``max_speed * dt``, as a new array (np.array of the three values). */
static PyObject *hand_advance(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "hand_advance(reference, target, max_speed, dt)");
        return NULL;
    }
    double r[3], t[3];
    double max_speed = PyFloat_AsDouble(args[2]), dt = PyFloat_AsDouble(args[3]);
    if (PyErr_Occurred() || array_doubles(args[0], 0, r, 3) < 0 || vec3(args[1], t) < 0)
        return NULL;
    double dx = t[0] - r[0], dy = t[1] - r[1], dz = t[2] - r[2];
    double dist = sqrt(dx * dx + dy * dy + dz * dz);
    double limit = max_speed * dt;
    if (dist > limit) {
        double k = limit / dist;
        dx = dx * k;
        dy = dy * k;
        dz = dz * k;
    }
    return array3(r[0] + dx, r[1] + dy, r[2] + dz);
}

/* The controller's joint indices, packed by HandController._native_indices (float64):
 * [n, dof ids (n), qpos ids (n)]. The arrays a body may replace (nominal, weights, limits) are
 * arguments. */
typedef struct {
    Py_ssize_t n;
    const double *dof, *qid;
} HandConsts;

static int hand_consts(PyObject *packed, HandConsts *c)
{
    Py_ssize_t size = PyBytes_Check(packed) ? PyBytes_GET_SIZE(packed) / 8 : 0;
    const double *v = size ? (const double *)PyBytes_AS_STRING(packed) : NULL;
    c->n = v ? (Py_ssize_t)v[0] : 0;
    if (c->n < 1 || size != 1 + 2 * c->n) {
        PyErr_SetString(PyExc_TypeError, "hand indices: expected the packed bytes");
        return -1;
    }
    c->dof = v + 1, c->qid = v + 1 + c->n;
    return 0;
}

/* hand_gather(indices, jacp, qpos, setpoint, nominal, weights, posture_gain, jac, jw, posture, x)
 *
 * The element-wise start of HandController.setpoints: ``jac = jacp[:, dof_ids]``,
 * ``posture = posture_gain * (nominal - setpoint)``, ``x = setpoint - qpos[qpos_ids] + posture``
 * (what jac.dot takes) and ``jw = jac * weights`` (per column). */
static PyObject *hand_gather(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    HandConsts c;
    if (nargs != 11) {
        PyErr_SetString(PyExc_TypeError, "hand_gather(indices, jacp, qpos, setpoint, nominal, weights, posture_gain, "
                                         "jac, jw, posture, x)");
        return NULL;
    }
    double gain = PyFloat_AsDouble(args[6]);
    if ((gain == -1.0 && PyErr_Occurred()) || hand_consts(args[0], &c) < 0)
        return NULL;
    Py_ssize_t n = c.n;
    Buffers b = {.n = 0};
    double *jacp = buf(&b, args[1], 0, 3), *q = jacp ? buf(&b, args[2], 0, 1) : NULL;
    double *sp = q ? buf(&b, args[3], 0, n) : NULL, *nominal = sp ? buf(&b, args[4], 0, n) : NULL;
    double *w = nominal ? buf(&b, args[5], 0, n) : NULL, *jac = w ? buf(&b, args[7], 1, 3 * n) : NULL;
    double *jw = jac ? buf(&b, args[8], 1, 3 * n) : NULL, *posture = jw ? buf(&b, args[9], 1, n) : NULL;
    double *x = posture ? buf(&b, args[10], 1, n) : NULL;
    if (x == NULL)
        goto fail;
    Py_ssize_t nv = b.view[0].len / 8 / 3, nq = b.view[1].len / 8;
    for (Py_ssize_t k = 0; k < n; k++)
        if (!(c.dof[k] >= 0 && c.dof[k] < nv && c.qid[k] >= 0 && c.qid[k] < nq)) {
            PyErr_SetString(PyExc_IndexError, "hand_gather: index out of range");
            goto fail;
        }
    for (Py_ssize_t r = 0; r < 3; r++)
        for (Py_ssize_t k = 0; k < n; k++) {
            jac[r * n + k] = jacp[r * nv + (Py_ssize_t)c.dof[k]];
            jw[r * n + k] = jac[r * n + k] * w[k];
        }
    for (Py_ssize_t k = 0; k < n; k++) {
        posture[k] = gain * (nominal[k] - sp[k]);
        x[k] = sp[k] - q[(Py_ssize_t)c.qid[k]] + posture[k];
    }
    release_all(&b);
    Py_RETURN_NONE;
fail:
    release_all(&b);
    return NULL;
}

/* hand_solve(jj, j, reference, site_xpos, site_id, damping2, y)
 *
 * The 3x3 middle of HandController.setpoints: the error of the hand the setpoints would give
 * (``reference - site - j``, j = jac.dot(x)), the damped system ``jj + l^2 I`` (jj = jw.dot(jw.T);
 * "+ 0.0" off the diagonal as in the Python) and its solution by geometry.solve3, into ``y``. */
static PyObject *hand_solve(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 7) {
        PyErr_SetString(PyExc_TypeError, "hand_solve(jj, j, reference, site_xpos, site_id, damping2, y)");
        return NULL;
    }
    double m[9], jv[3], ref[3], site[3];
    Py_ssize_t sid = PyLong_AsSsize_t(args[4]);
    double l2 = PyFloat_AsDouble(args[5]);
    if (PyErr_Occurred() || array_doubles(args[0], 0, m, 9) < 0 || array_doubles(args[1], 0, jv, 3) < 0
        || array_doubles(args[2], 0, ref, 3) < 0 || array_doubles(args[3], 3 * sid, site, 3) < 0)
        return NULL;
    double x = (ref[0] - site[0]) - jv[0], y = (ref[1] - site[1]) - jv[1], z = (ref[2] - site[2]) - jv[2];
    double a = m[0] + l2, b_ = m[1] + 0.0, c = m[2] + 0.0, d = m[3] + 0.0, e = m[4] + l2, f = m[5] + 0.0,
           g = m[6] + 0.0, h = m[7] + 0.0, i = m[8] + l2;
    /* geometry.solve3 */
    double ei_fh = e * i - f * h, fg_di = f * g - d * i, dh_eg = d * h - e * g;
    double det = a * ei_fh + b_ * fg_di + c * dh_eg;
    double sol[3] = {
        (x * ei_fh + b_ * (f * z - y * i) + c * (y * h - e * z)) / det,
        (a * (y * i - f * z) + x * fg_di + c * (d * z - y * g)) / det,
        (a * (e * z - y * h) + b_ * (y * g - d * z) + x * dh_eg) / det,
    };
    Buffers bf = {.n = 0};
    double *out = buf(&bf, args[6], 1, 3);
    if (out != NULL)
        memcpy(out, sol, sizeof(sol));
    release_all(&bf);
    if (out == NULL)
        return NULL;
    Py_RETURN_NONE;
}

/* hand_finish(z, weights, posture, setpoint, max_joint_step, lower, upper, out)
 *
 * The end of HandController.setpoints: ``dq = weights * z + posture`` (z = y.dot(jw)), scaled down
 * if its largest step exceeds ``max_joint_step``, plus the setpoint, clipped as
 * np.maximum(dq, lower) then np.minimum(dq, upper); into ``out``. */
static PyObject *hand_finish(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "hand_finish(z, weights, posture, setpoint, max_step, lower, upper, out)");
        return NULL;
    }
    double max_step = PyFloat_AsDouble(args[4]);
    if (max_step == -1.0 && PyErr_Occurred())
        return NULL;
    Buffers b = {.n = 0};
    double *z = buf(&b, args[0], 0, 1);
    if (z == NULL)
        goto fail;
    Py_ssize_t n = b.view[0].len / 8;
    double *w = buf(&b, args[1], 0, n), *posture = w ? buf(&b, args[2], 0, n) : NULL;
    double *sp = posture ? buf(&b, args[3], 0, n) : NULL, *lo = sp ? buf(&b, args[5], 0, n) : NULL;
    double *hi = lo ? buf(&b, args[6], 0, n) : NULL, *dq = hi ? buf(&b, args[7], 1, n) : NULL;
    if (dq == NULL)
        goto fail;
    double mx = 0.0, mn = 0.0;
    for (Py_ssize_t k = 0; k < n; k++) {
        dq[k] = w[k] * z[k] + posture[k];
        if (k == 0 || dq[k] > mx) /* Python's max() and min() of the list */
            mx = dq[k];
        if (k == 0 || dq[k] < mn)
            mn = dq[k];
    }
    double step = py_max(mx, -mn);
    if (step > max_step) {
        double scale = max_step / step;
        for (Py_ssize_t k = 0; k < n; k++)
            dq[k] *= scale;
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        double v = dq[k] + sp[k];
        v = (v >= lo[k] || isnan(v)) ? v : lo[k];     /* np.maximum */
        dq[k] = (v <= hi[k] || isnan(v)) ? v : hi[k]; /* np.minimum */
    }
    release_all(&b);
    Py_RETURN_NONE;
fail:
    release_all(&b);
    return NULL;
}

/* ---- the step skeleton (visuomotor_gym/core/env.py) ------------------------------------------------ */

/* vector3(values) -> np.array(values) for a list or tuple of three floats (a new float64 array). */
static PyObject *vector3(PyObject *self, PyObject *arg)
{
    double v[3];
    if (seq_doubles(arg, v, 3) < 0)
        return NULL;
    return array3(v[0], v[1], v[2]);
}

/* check_action(action, n) -> (a, values) or None
 *
 * The common case of VisuomotorEnv._check_action: a float32 or float64 numpy array of shape (n,)
 * whose values are all finite and in [-1, 1] gives ``a = action.astype(np.float64)`` (a new
 * array; float32 -> float64 is exact) and ``a.tolist()``. Anything else gives None: the Python
 * method then checks, raises or clips. */
static PyObject *check_action(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "check_action(action, n)");
        return NULL;
    }
    Py_ssize_t n = PyLong_AsSsize_t(args[1]);
    if (n == -1 && PyErr_Occurred())
        return NULL;
    if (Py_TYPE(args[0]) != (PyTypeObject *)np_ndarray || n < 1 || n > 64)
        Py_RETURN_NONE;
    Py_buffer view;
    if (PyObject_GetBuffer(args[0], &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        Py_RETURN_NONE;
    }
    double v[64];
    const char *f = view.format ? view.format : "";
    int is_f32 = strcmp(f, "f") == 0 || strcmp(f, "<f") == 0 || strcmp(f, "=f") == 0;
    int is_f64 = strcmp(f, "d") == 0 || strcmp(f, "<d") == 0 || strcmp(f, "=d") == 0;
    int fine = view.ndim == 1 && view.shape != NULL && view.shape[0] == n && (is_f32 || is_f64);
    for (Py_ssize_t i = 0; i < n && fine; i++) {
        v[i] = is_f32 ? (double)((const float *)view.buf)[i] : ((const double *)view.buf)[i];
        fine = isfinite(v[i]) && v[i] >= -1.0 && v[i] <= 1.0;
    }
    PyBuffer_Release(&view);
    if (!fine)
        Py_RETURN_NONE;
    PyObject *len = PyLong_FromSsize_t(n), *a = len ? PyObject_CallOneArg(np_empty, len) : NULL;
    Py_XDECREF(len);
    if (a == NULL)
        return NULL;
    Py_buffer out;
    if (f64_buffer(a, &out, 1) < 0) {
        Py_DECREF(a);
        return NULL;
    }
    memcpy(out.buf, v, (size_t)n * sizeof(double));
    PyBuffer_Release(&out);
    PyObject *values = list_of(v, n);
    if (values == NULL) {
        Py_DECREF(a);
        return NULL;
    }
    return Py_BuildValue("(NN)", a, values);
}

/* float32_array(values) -> array or None
 *
 * ``np.array(values, dtype=np.float32)`` of VisuomotorEnv._observe: each value as a double,
 * rounded to float32 as numpy casts. Only floats and ints (bools) are taken; anything else gives
 * None (the Python builds the array). */
static PyObject *float32_array(PyObject *self, PyObject *values)
{
    if (!PyList_Check(values)) {
        PyErr_SetString(PyExc_TypeError, "float32_array(values: list)");
        return NULL;
    }
    Py_ssize_t n = PyList_GET_SIZE(values);
    PyObject *len = PyLong_FromSsize_t(n);
    if (len == NULL)
        return NULL;
    PyObject *call[2] = {len, np_float32};
    PyObject *array = PyObject_Vectorcall(np_empty, call, 2, NULL); /* np.empty(n, np.float32) */
    Py_DECREF(len);
    if (array == NULL)
        return NULL;
    Py_buffer view;
    if (PyObject_GetBuffer(array, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        Py_DECREF(array);
        return NULL;
    }
    int ok = view.itemsize == 4 && view.format != NULL
             && (strcmp(view.format, "f") == 0 || strcmp(view.format, "<f") == 0 || strcmp(view.format, "=f") == 0)
             && view.len == 4 * n;
    float *out = (float *)view.buf;
    for (Py_ssize_t i = 0; i < n && ok; i++) {
        PyObject *x = PyList_GET_ITEM(values, i);
        double v = 0.0;
        if (PyFloat_Check(x))
            v = PyFloat_AS_DOUBLE(x);
        else if (PyLong_Check(x)) {
            v = PyLong_AsDouble(x);
            if (v == -1.0 && PyErr_Occurred()) {
                PyErr_Clear();
                ok = 0;
            }
        } else
            ok = 0;
        out[i] = (float)v;
    }
    PyBuffer_Release(&view);
    if (ok)
        return array;
    Py_DECREF(array);
    Py_RETURN_NONE;
}

/* ---- module ----------------------------------------------------------------------------------- */

static PyMethodDef kernel_methods[] = {
    {"plant_step", (PyCFunction)(void (*)(void))plant_step, METH_FASTCALL,
     "OculomotorPlant.step unless a saccade starts (see _kernels.c)."},
    {"eye_command", (PyCFunction)(void (*)(void))eye_command, METH_FASTCALL, "Eye.command (see _kernels.c)."},
    {"eye_apply", (PyCFunction)(void (*)(void))eye_apply, METH_FASTCALL, "Eye.apply (see _kernels.c)."},
    {"hand_advance", (PyCFunction)(void (*)(void))hand_advance, METH_FASTCALL, "HandController.advance_reference."},
    {"hand_gather", (PyCFunction)(void (*)(void))hand_gather, METH_FASTCALL, "HandController.setpoints, start."},
    {"hand_solve", (PyCFunction)(void (*)(void))hand_solve, METH_FASTCALL, "HandController.setpoints, 3x3 solve."},
    {"hand_finish", (PyCFunction)(void (*)(void))hand_finish, METH_FASTCALL, "HandController.setpoints, end."},
    {"vector3", (PyCFunction)vector3, METH_O, "np.array of three floats."},
    {"check_action", (PyCFunction)(void (*)(void))check_action, METH_FASTCALL,
     "VisuomotorEnv._check_action, common case."},
    {"float32_array", (PyCFunction)float32_array, METH_O, "np.array(values, dtype=np.float32)."},
    {"retina_see_all", (PyCFunction)(void (*)(void))retina_see_all, METH_FASTCALL,
     "Retina._see_all (see _kernels.c)."},
    {"retina_see_periphery", (PyCFunction)(void (*)(void))retina_see_periphery, METH_FASTCALL,
     "Retina._see_all_periphery (see _kernels.c)."},
    {"crowding_groups", (PyCFunction)(void (*)(void))crowding_groups, METH_FASTCALL,
     "periphery.crowding_groups (see _kernels.c)."},
    {"pooled", (PyCFunction)(void (*)(void))pooled, METH_FASTCALL, "periphery.pooled (see _kernels.c)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef kernel_module = {PyModuleDef_HEAD_INIT, "_kernels",
                                           "Compiled mirrors of per-step hot loops.", -1, kernel_methods};

PyMODINIT_FUNC PyInit__kernels(void)
{
    PyObject *math = PyImport_ImportModule("math");
    if (math == NULL)
        return NULL;
    math_hypot = PyObject_GetAttrString(math, "hypot");
    Py_DECREF(math);
    if (math_hypot == NULL)
        return NULL;
    PyObject *numpy = PyImport_ImportModule("numpy");
    if (numpy == NULL)
        return NULL;
    np_empty = PyObject_GetAttrString(numpy, "empty");
    np_ndarray = PyObject_GetAttrString(numpy, "ndarray");
    np_float32 = PyObject_GetAttrString(numpy, "float32");
    np_float64_dtype = PyObject_CallMethod(numpy, "dtype", "s", "float64");
    Py_DECREF(numpy);
    if (np_float64_dtype == NULL || (s_dtype = PyUnicode_InternFromString("dtype")) == NULL
        || (float_zero = PyFloat_FromDouble(0.0)) == NULL)
        return NULL;
    if (np_ndarray == NULL || np_float32 == NULL)
        return NULL;
    if (np_empty == NULL || (int_three = PyLong_FromLong(3)) == NULL)
        return NULL;
#define INTERN(var, name)                                                                                             \
    if ((var = PyUnicode_InternFromString(name)) == NULL)                                                             \
        return NULL;
    INTERN(s_time, "time")
    INTERN(s_suppressed, "_suppressed")
    INTERN(s_prev_request, "_prev_request")
    INTERN(s_last_sample, "_last_sample")
    INTERN(s_drive_queue, "_drive_queue")
    INTERN(s_drive, "_drive")
    INTERN(s_goal, "_goal")
    INTERN(s_pursuit_omega, "pursuit_omega")
    INTERN(s_saccade, "saccade")
    INTERN(s_omega, "_omega")
    INTERN(s_onset, "onset")
    INTERN(s_duration, "duration")
    INTERN(s_amplitude, "amplitude")
    INTERN(s_arc, "_arc")
    INTERN(s_axis, "axis")
    INTERN(s_gaze, "gaze")
    INTERN(s_hidden, "hidden")
    INTERN(s_state, "state")
    INTERN(s_last_onset, "last_onset")
    INTERN(s_standard_normal, "standard_normal")
    INTERN(s_kind, "kind")
    INTERN(s_group, "group")
    INTERN(s_name, "name")
    INTERN(s_values, "values")

#undef INTERN
    return PyModule_Create(&kernel_module);
}
