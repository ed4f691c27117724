"""Additive Runge-Kutta (IMEX) pairs as validated tables, for a split f = (f - J y) + J y.

An additive method pairs an explicit tableau AE (for the nonstiff part) with an ESDIRK tableau AI
(for the stiff part, here the linear J y), both with the same weights b, b_hat and nodes c. The
tables are kept in the published form, as exact rationals, checked on construction against the
order conditions of each tableau alone and the coupling conditions of the pair (Butcher trees
whose non-root vertices are each labelled E or I, the additive methods' order conditions), and
handed to a compiled loop as floats (ArkArrays).

C.A. Kennedy, M.H. Carpenter, "Additive Runge-Kutta schemes for convection-diffusion-reaction
equations", Appl. Numer. Math. 44 (2003) 139-181: ARK4(3)6L[2]SA (6 stages, order 4, embedded
3, gamma = 1/4) and ARK5(4)8L[2]SA (8 stages, order 5, embedded 4, gamma = 41/200); the ESDIRK
parts are stiffly accurate and L-stable. The rationals were read from SUNDIALS (LLNL/sundials),
src/arkode/arkode_butcher_erk.def and arkode_butcher_dirk.def (ARKODE_ARK436L2SA_{ERK,DIRK}_6_3_4,
ARKODE_ARK548L2SA_{ERK,DIRK}_8_4_5), which carry the paper's values. Some of the paper's entries
are rational approximations (denominators near 1e13) of irrational values: exactly, they meet
every condition checked here to ~3e-26, far below the rounding of a double.
"""

from collections import namedtuple
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import numpy as np

# What the compiled loop reads. With Z_i = Y_i - y_n, F_j = f(Y_j) and D = AI - AE, each stage
# solves (I - h gamma J) Z_i = h sum_{j<i} [AE_ij F_j + D_ij J Z_j] (Z_0 = 0); y_new = y_n +
# h sum b_j F_j and the error estimate h sum (b_j - b_hat_j) F_j. The J y_n terms of the split
# cancel only because AE and AI have the same row sums c (checked here): no product with y_n.
ArkArrays = namedtuple("ArkArrays", ["AE", "AI", "D", "b", "b_hat", "c", "gamma", "expo"])

# In doubles the tables meet every condition to < 2e-15, and to < 2e-16 of the size of its terms
# (the same sum with |entries|, at least 1); a wrong digit shows as >> 1e-13. A condition may
# miss by TOL times its size: rounding grows with it (ARK5(4)8L[2]SA's explicit entries reach 15,
# its order-5 chains a size of 3e5), and a wrong entry still fails its row sum (size < 30).
TOL = 1e-13

# Trees are checked up to this order (the classical conditions of order 5 are 17 trees).
MAX_ORDER = 5


# --- Butcher trees with labelled vertices -------------------------------------------------------
# A tree is the sorted tuple of its root's children, each a (label, subtree) pair: label "E" or
# "I" says which tableau (AE or AI) joins the child to its parent. The root carries the weights.


def _order(tree):
    return 1 + sum(_order(sub) for _, sub in tree)


def _density(tree):
    """gamma(t) of Butcher: the order times the densities of the subtrees."""
    d = _order(tree)
    for _, sub in tree:
        d *= _density(sub)
    return d


@lru_cache(maxsize=None)
def labelled_trees(order):
    """Every tree of the given order, each non-root vertex labelled E or I, each once."""
    if order == 1:
        return ((),)
    items = [(lab, t) for k in range(1, order) for t in labelled_trees(k) for lab in "EI"]
    found = []

    def grow(start, left, chosen):
        # children as a multiset: indices never decrease, so each set of children comes once
        if left == 0:
            found.append(tuple(sorted(chosen)))
            return
        for idx in range(start, len(items)):
            k = _order(items[idx][1])
            if k <= left:
                grow(idx, left - k, chosen + [items[idx]])

    grow(0, order - 1, [])
    return tuple(found)


def tree_labels(tree):
    """The set of labels on the tree's vertices (empty for the single vertex)."""
    out = set()
    for lab, sub in tree:
        out |= {lab} | tree_labels(sub)
    return out


def tree_name(tree):
    """Bracket notation: the root's children in [...], a child's label before its own children:
    "[E[I]]" is the chain sum b_i AE_ij AI_jk, "[E, I]" the bush sum b_i c_i c_i."""
    if not tree:
        return "[]"
    return "[" + ", ".join(lab + (tree_name(sub) if sub else "") for lab, sub in tree) + "]"


def _mat_vec(M, v):
    return [sum(M[i][j] * v[j] for j in range(len(v))) for i in range(len(M))]


def _phi(tree, mats):
    """The elementary weight vector of the tree: per stage, the product over the children of
    (A_label Phi(child)); plain loops in a fixed order."""
    s = len(mats["E"])
    out = [1.0] * s
    for lab, sub in tree:
        v = _mat_vec(mats[lab], _phi(sub, mats))
        out = [x * y for x, y in zip(out, v)]
    return out


# --- The tables ----------------------------------------------------------------------------------


def _value(text):
    """A published coefficient ("-1743/31250", "0.25") as the nearest double, via the exact value."""
    return float(Fraction(text))


def _lower(rows, s, diagonal):
    """Lower-triangular rows as a square float list (rows of length i, or i + 1 with diagonal)."""
    M = [[0.0] * s for _ in range(s)]
    for i, row in enumerate(rows):
        if len(row) != i + diagonal:
            raise ValueError(f"row {i} has {len(row)} entries, expected {i + diagonal}")
        for j, x in enumerate(row):
            M[i][j] = _value(x)
    return M


Condition = namedtuple("Condition", ["label", "residual", "bound"])


@dataclass(frozen=True)
class ArkTableau:
    name: str
    order: int              # order of the propagated solution (b), of each tableau and coupled
    embedded_order: int     # order of b_hat (sets the step-size exponent)
    gamma: str              # the ESDIRK diagonal
    ae: tuple               # explicit rows, strictly lower (row i has i entries)
    ai: tuple               # implicit rows with the diagonal (row i has i + 1 entries)
    b: tuple
    b_hat: tuple
    c: tuple

    def __post_init__(self):
        s = len(self.c)
        if not (len(self.ae) == len(self.ai) == len(self.b) == len(self.b_hat) == s):
            raise ValueError(f"{self.name}: inconsistent stage counts")
        if not 1 <= self.embedded_order < self.order <= MAX_ORDER:
            raise ValueError(f"{self.name}: orders {self.order}({self.embedded_order}) not checkable "
                             f"(conditions implemented up to order {MAX_ORDER})")
        try:
            _lower(self.ae, s, 0), _lower(self.ai, s, 1)
        except ValueError as err:
            raise ValueError(f"{self.name}: {err}") from None
        self._check_structure()
        for cond in self.conditions():
            if not abs(cond.residual) <= TOL * cond.bound:
                raise ValueError(f"{self.name}: fails the condition {cond.label} "
                                 f"(residual {cond.residual:.3e})")

    def _check_structure(self):
        """ESDIRK form: AI[0][0] = 0 (the first stage is explicit: Z_0 = 0), gamma on the rest of
        the diagonal; stiffly accurate: AI's last row is b (y_new is the last stage)."""
        if Fraction(self.ai[0][0]) != 0:
            raise ValueError(f"{self.name}: fails the condition AI[0][0] = 0 (first stage explicit)")
        for i in range(1, self.stages):
            if Fraction(self.ai[i][i]) != Fraction(self.gamma):
                raise ValueError(f"{self.name}: fails the condition AI[{i}][{i}] = gamma")
        if [Fraction(x) for x in self.ai[-1]] != [Fraction(x) for x in self.b]:
            raise ValueError(f"{self.name}: fails the condition stiffly accurate (last row of AI = b)")

    @property
    def stages(self):
        return len(self.c)

    def matrices(self):
        """AE, AI (square float lists), b, b_hat, c (float lists), gamma."""
        s = self.stages
        return (_lower(self.ae, s, 0), _lower(self.ai, s, 1), [_value(x) for x in self.b],
                [_value(x) for x in self.b_hat], [_value(x) for x in self.c], _value(self.gamma))

    def conditions(self):
        """Every checked condition as (label, residual, bound): the row sums (c = AE 1 = AI 1), then
        for b every labelled tree up to the order and for b_hat up to the embedded order (all-E
        trees: the explicit tableau's classical conditions; all-I: the implicit one's; mixed: the
        coupling). The bound scales TOL by the size of the terms (the same sum with |entries|)."""
        AE, AI, b, b_hat, c, _ = self.matrices()
        out = []
        for tag, M in (("AE", AE), ("AI", AI)):
            for i in range(self.stages):
                size = max(1.0, sum(abs(x) for x in M[i]))
                out.append(Condition(f"row sum {tag}[{i}] = c[{i}]", sum(M[i]) - c[i], size))
        mats = {"E": AE, "I": AI}
        absolute = {k: [[abs(x) for x in row] for row in M] for k, M in mats.items()}
        for which, w, top in (("b", b, self.order), ("b_hat", b_hat, self.embedded_order)):
            w_abs = [abs(x) for x in w]
            for k in range(1, top + 1):
                for tree in labelled_trees(k):
                    lhs = sum(x * y for x, y in zip(w, _phi(tree, mats)))
                    size = sum(x * y for x, y in zip(w_abs, _phi(tree, absolute)))
                    out.append(Condition(_condition_label(which, tree), lhs - 1.0 / _density(tree),
                                         max(1.0, size)))
        return out

    def arrays(self):
        """ArkArrays for the compiled loop (see the comment at ArkArrays)."""
        AE, AI, b, b_hat, c, g = self.matrices()
        AE, AI = np.array(AE), np.array(AI)
        return ArkArrays(AE, AI, AI - AE, np.array(b), np.array(b_hat), np.array(c), g,
                         -1.0 / (self.embedded_order + 1))


def _condition_label(which, tree):
    """"b: coupling order 3 tree [E[I]] = 1/6": the weights, which tableaus the tree draws on (the
    explicit one alone, the implicit one alone, or both: a coupling condition), the tree."""
    k = _order(tree)
    if k == 1:
        return f"{which}: order 1 sum {which}_i = 1"
    kind = {"E": "explicit", "I": "implicit"}.get("".join(tree_labels(tree)), "coupling")
    return f"{which}: {kind} order {k} tree {tree_name(tree)} = 1/{_density(tree)}"


# ARK4(3)6L[2]SA, Kennedy & Carpenter (2003); the rationals as SUNDIALS carries them (module
# docstring). b is the last row of AI (stiffly accurate).
_ARK436_B = ("82889/524892", "0", "15625/83664", "69875/102672", "-2260/8211", "1/4")
ARK436L2SA = ArkTableau(
    "ark436l2sa", 4, 3, "1/4",
    ae=(
        (),
        ("1/2",),
        ("13861/62500", "6889/62500"),
        ("-116923316275/2393684061468", "-2731218467317/15368042101831", "9408046702089/11113171139209"),
        ("-451086348788/2902428689909", "-2682348792572/7519795681897", "12662868775082/11960479115383",
         "3355817975965/11060851509271"),
        ("647845179188/3216320057751", "73281519250/8382639484533", "552539513391/3454668386233",
         "3354512671639/8306763924573", "4040/17871"),
    ),
    ai=(
        ("0",),
        ("1/4", "1/4"),
        ("8611/62500", "-1743/31250", "1/4"),
        ("5012029/34652500", "-654441/2922500", "174375/388108", "1/4"),
        ("15267082809/155376265600", "-71443401/120774400", "730878875/902184768", "2285395/8070912", "1/4"),
        _ARK436_B,
    ),
    b=_ARK436_B,
    b_hat=("4586570599/29645900160", "0", "178811875/945068544", "814220225/1159782912",
           "-3700637/11593932", "61727/225920"),
    c=("0", "1/2", "83/250", "31/50", "17/20", "1"),
)

# ARK5(4)8L[2]SA, Kennedy & Carpenter (2003); the rationals as SUNDIALS carries them.
_ARK548_B = ("-872700587467/9133579230613", "0", "0", "22348218063261/9555858737531",
             "-1143369518992/8141816002931", "-39379526789629/19018526304540",
             "32727382324388/42900044865799", "41/200")
ARK548L2SA = ArkTableau(
    "ark548l2sa", 5, 4, "41/200",
    ae=(
        (),
        ("41/100",),
        ("367902744464/2072280473677", "677623207551/8224143866563"),
        ("1268023523408/10340822734521", "0", "1029933939417/13636558850479"),
        ("14463281900351/6315353703477", "0", "66114435211212/5879490589093",
         "-54053170152839/4284798021562"),
        ("14090043504691/34967701212078", "0", "15191511035443/11219624916014",
         "-18461159152457/12425892160975", "-281667163811/9011619295870"),
        ("19230459214898/13134317526959", "0", "21275331358303/2942455364971",
         "-38145345988419/4862620318723", "-1/8", "-1/8"),
        ("-19977161125411/11928030595625", "0", "-40795976796054/6384907823539",
         "177454434618887/12078138498510", "782672205425/8267701900261",
         "-69563011059811/9646580694205", "7356628210526/4942186776405"),
    ),
    ai=(
        ("0",),
        ("41/200", "41/200"),
        ("41/400", "-567603406766/11931857230679", "41/200"),
        ("683785636431/9252920307686", "0", "-110385047103/1367015193373", "41/200"),
        ("3016520224154/10081342136671", "0", "30586259806659/12414158314087",
         "-22760509404356/11113319521817", "41/200"),
        ("218866479029/1489978393911", "0", "638256894668/5436446318841",
         "-1179710474555/5321154724896", "-60928119172/8023461067671", "41/200"),
        ("1020004230633/5715676835656", "0", "25762820946817/25263940353407",
         "-2161375909145/9755907335909", "-211217309593/5846859502534",
         "-4269925059573/7827059040749", "41/200"),
        _ARK548_B,
    ),
    b=_ARK548_B,
    b_hat=("-975461918565/9796059967033", "0", "0", "78070527104295/32432590147079",
           "-548382580838/3424219808633", "-33438840321285/15594753105479",
           "3629800801594/4656183773603", "4035322873751/18575991585200"),
    c=("0", "41/100", "2935347310677/11292855782101", "1426016391358/7196633302097", "92/100",
       "24/100", "3/5", "1"),
)

ARK_TABLEAUS = {t.name: t for t in (ARK436L2SA, ARK548L2SA)}
