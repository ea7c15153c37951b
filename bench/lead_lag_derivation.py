import sympy as sp
r, psi, mu, nb, dl = sp.symbols('r psi mu n_beta delta', real=True)
th0t, b0t, lam0t, muzt = sp.symbols('theta0_t beta0_t lambda0_t muz_t', real=True)
eps = sp.Symbol('eps')
names = ['b0','b1c','b1s','db0','db1c','db1s','l0','l1c','l1s','t0','t1c','t1s','muz','q','p','z1c','z1s','dz1c','dz1s']
S = sp.symbols(names, real=True)
v = dict(zip(names, S))
c, s = sp.cos(psi), sp.sin(psi)
zeta = v['z1c']*c + v['z1s']*s
dzeta = (v['dz1c']+v['z1s'])*c + (v['dz1s']-v['z1c'])*s
beta = v['b0'] + v['b1c']*c + v['b1s']*s
dbeta = v['db0'] + (v['db1c']+v['b1s'])*c + (v['db1s']-v['b1c'])*s
UT = r*(1-dzeta) + mu*sp.sin(psi-zeta)
UP = muzt + v['muz'] - (lam0t + v['l0'] + r*(v['l1c']*c + v['l1s']*s)) - r*dbeta - mu*(b0t+beta)*sp.cos(psi-zeta) + r*(v['p']*s + v['q']*c)
th = th0t + v['t0'] + v['t1c']*c + v['t1s']*s
lift = th*UT**2 + UP*UT
drag = -(th*UT*UP + UP**2) + dl*UT**2
def lin(f):
    out = {}
    sub0 = {x: 0 for x in S}
    for n, x in v.items():
        d = sp.diff(f, x).subs(sub0)
        out[n] = sp.expand(sp.expand_trig(d))
    return out
def avg(e):
    return sp.simplify(sp.integrate(sp.expand(e), (psi, 0, 2*sp.pi))/(2*sp.pi))
def rint(e):
    return sp.integrate(e, (r, 0, 1))
F = lin(4*nb*r*lift)
Z = lin(4*nb*r*drag)
L = lin(sp.Rational(1,2)*lift)
proj = [1, 2*c, 2*s]
res = {}
for nm, dct, wts in (('flapaero', F, proj), ('lagaero', Z, [2*c, 2*s]), ('loads', L, [1, -r*c, -r*s])):
    rows = []
    for w in wts:
        row = {}
        for n in names:
            val = sp.factor(sp.expand(avg(rint(sp.expand(w*dct[n])))))
            if val != 0:
                row[n] = val
        rows.append(row)
    res[nm] = rows
import pickle
for k, rows in res.items():
    print('==', k)
    for i, row in enumerate(rows):
        print(i, row)
pickle.dump(res, open('/tmp/lag/res.pkl','wb'))
